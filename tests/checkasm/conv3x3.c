/* The denoiser's kernel table (denoise/conv.h): every level's conv3x3
 * against ptr_conv3x3_c, bit for bit, through the checked call, on layers
 * of random shape (1 to 40 pixels wide, 1 to 5 rows, 16 to 160 input and
 * 16 to 112 output channels; a tenth 41 to 340 wide, of 1 or 2 rows and 16
 * to 48 channels; ReLU on or off) holding random values of mixed
 * signs, or adversarial ones: NaN, infinities, signed zeros, denormals,
 * values whose products and sums overflow, all-negative sums for the ReLU
 * to zero. The output's border and the memory around the output hold a
 * guard value that must survive. The input's border holds values too (the
 * network's are zeros), so that a kernel reading the wrong pixel shows. */
#include <float.h>
#include <inttypes.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "checkasm.h"

/* The checked call's asm reads ConvCall at these offsets. */
_Static_assert(offsetof(ConvCall, src) == 8 && offsetof(ConvCall, width) == 32 &&
               offsetof(ConvCall, in_channels) == 48 && offsetof(ConvCall, relu) == 64,
               "ConvCall layout");

enum { LAYERS = 240, GUARD_FLOATS = 64 };

/* A signalling NaN: no arithmetic makes one, so it survives only where
 * nothing was written. */
static const uint32_t guard_bits = 0x7fbadbadu;

typedef enum Values {
    VALUES_RANDOM,   /* uniform, mixed signs */
    VALUES_SPECIAL,  /* a few NaN, infinite, signed zero, denormal, huge */
    VALUES_OVERFLOW, /* products near FLT_MAX: sums overflow, inf - inf */
    VALUES_NEGATIVE, /* every sum negative: the ReLU zeroes all */
    VALUES_ZEROS,    /* zeros of one sign a layer, a few denormals: the sign of a zero sum */
    VALUES_KINDS,
} Values;

/* How a layer's values are drawn: their kind, the share of special values,
 * the signs of the zeros layers' inputs, weights and bias (bits 0, 1, 2). */
typedef struct Draw {
    Values kind;
    float special_share;
    unsigned signs;
} Draw;

static const char *const values_names[VALUES_KINDS] = {
    "random", "special", "overflow", "negative", "zeros",
};

static float from_bits(uint32_t bits)
{
    float f;
    memcpy(&f, &bits, sizeof f);
    return f;
}

static uint32_t to_bits(float f)
{
    uint32_t bits;
    memcpy(&bits, &f, sizeof bits);
    return bits;
}

static int is_quiet_nan(uint32_t bits)
{
    return (bits & 0x7fc00000u) == 0x7fc00000u;
}

/* Uniform in (-magnitude, magnitude), for any finite magnitude. */
static float signed_uniform(PtrRng *rng, float magnitude)
{
    return magnitude * (2.0f * ptr_rng_float(rng) - 1.0f);
}

static float special_value(PtrRng *rng)
{
    switch (ptr_rng_next(rng) % 10) {
    case 0: return from_bits(0x7fc00000u | (uint32_t)(ptr_rng_next(rng) & 0x3fffff)); /* NaN */
    case 1: return from_bits(0xffc00000u | (uint32_t)(ptr_rng_next(rng) & 0x3fffff)); /* -NaN */
    case 2: return INFINITY;
    case 3: return -INFINITY;
    case 4: return -0.0f;
    case 5: return 0.0f;
    case 6: return signed_uniform(rng, 0x1p-126f); /* denormal */
    case 7: return ptr_rng_float(rng) < 0.5f ? FLT_MAX : -FLT_MAX;
    case 8: return signed_uniform(rng, 1e30f);
    default: return ptr_rng_float(rng) < 0.5f ? FLT_MIN : -FLT_MIN;
    }
}

/* One value of the input (role 0), the weights (1) or the bias (2). */
static float draw(const Draw *d, int role, PtrRng *rng)
{
    float sign = d->signs >> role & 1 ? -1.0f : 1.0f;
    switch (d->kind) {
    case VALUES_SPECIAL:
        if (ptr_rng_float(rng) < d->special_share)
            return special_value(rng);
        return signed_uniform(rng, 1.0f);
    case VALUES_OVERFLOW:
        return signed_uniform(rng, role == 2 ? 1e38f : 6e18f);
    case VALUES_NEGATIVE:
        return role == 0 ? uniform(rng, 0.0f, 1.0f) : -uniform(rng, 0.0f, 1.0f);
    case VALUES_ZEROS:
        if (role == 1)
            return sign * uniform(rng, 0.0f, 1.0f);
        return sign * (ptr_rng_float(rng) < 0.002f ? uniform(rng, 0.0f, 0x1p-126f) : 0.0f);
    default:
        return signed_uniform(rng, role == 1 ? 0.1f : 1.0f);
    }
}

/* 64-byte aligned floats, count rounded up to whole cache lines. */
static float *aligned_floats(size_t count)
{
    size_t bytes = (count * sizeof(float) + 63) / 64 * 64;
    float *p = aligned_alloc(64, bytes);
    if (!p) {
        fprintf(stderr, "check_conv3x3: out of memory\n");
        exit(2);
    }
    return p;
}

typedef struct Layer {
    size_t width, rows, in_channels, out_channels;
    int relu;
    Values kind;
    float *src, *weights, *bias;
} Layer;

static void make_layer(Layer *l, PtrRng *rng)
{
    l->width = 1 + ptr_rng_next(rng) % 40;
    l->rows = 1 + ptr_rng_next(rng) % 5;
    l->in_channels = PTR_CONV_BLOCK * (1 + ptr_rng_next(rng) % 10);
    l->out_channels = PTR_CONV_BLOCK * (1 + ptr_rng_next(rng) % 7);
    if (ptr_rng_float(rng) < 0.1f) { /* a wide row, kept cheap for the reference */
        l->width = 41 + ptr_rng_next(rng) % 300;
        l->rows = 1 + ptr_rng_next(rng) % 2;
        l->in_channels = l->out_channels = PTR_CONV_BLOCK * (1 + ptr_rng_next(rng) % 3);
    }
    l->relu = ptr_rng_float(rng) < 0.5f;
    static const float special_shares[] = { 0.001f, 0.005f, 0.03f };
    Draw d = { ptr_rng_float(rng) < 0.5f ? VALUES_RANDOM
                                         : (Values)(1 + ptr_rng_next(rng) % (VALUES_KINDS - 1)),
               special_shares[ptr_rng_next(rng) % 3], (unsigned)(ptr_rng_next(rng) % 8) };
    l->kind = d.kind;
    size_t src_count = (l->rows + 2) * (l->width + 2) * l->in_channels;
    size_t weight_count = ptr_conv_weight_count(l->in_channels, l->out_channels);
    l->src = aligned_floats(src_count);
    l->weights = aligned_floats(weight_count);
    l->bias = aligned_floats(l->out_channels);
    for (size_t i = 0; i < src_count; i++)
        l->src[i] = draw(&d, 0, rng);
    for (size_t i = 0; i < weight_count; i++)
        l->weights[i] = draw(&d, 1, rng);
    for (size_t o = 0; o < l->out_channels; o++)
        l->bias[o] = draw(&d, 2, rng);
}

static void free_layer(Layer *l)
{
    free(l->src);
    free(l->weights);
    free(l->bias);
}

/* The output's frame: a guard, the padded rows (rows + 2 of width + 2
 * pixels), a guard; every float the guard value. */
static size_t frame_count(const Layer *l)
{
    return GUARD_FLOATS + (l->rows + 2) * (l->width + 2) * l->out_channels + GUARD_FLOATS;
}

static float *guarded_frame(const Layer *l)
{
    size_t count = frame_count(l);
    float *frame = aligned_floats(count);
    for (size_t i = 0; i < count; i++)
        frame[i] = from_bits(guard_bits);
    return frame;
}

/* The first pixel the kernel writes: row 1, column 1 of the padded rows. */
static float *frame_dst(const Layer *l, float *frame)
{
    return frame + GUARD_FLOATS + (l->width + 2 + 1) * l->out_channels;
}

static int is_interior(const Layer *l, size_t i)
{
    if (i < GUARD_FLOATS)
        return 0;
    size_t pixel = (i - GUARD_FLOATS) / l->out_channels;
    size_t y = pixel / (l->width + 2), x = pixel % (l->width + 2);
    return y >= 1 && y <= l->rows && x >= 1 && x <= l->width;
}

typedef struct ConvTally {
    uint64_t differ[PTR_CPU_LEVEL_COUNT];       /* layers with an output not c's */
    uint64_t border[PTR_CPU_LEVEL_COUNT];       /* layers with a guard overwritten */
    uint64_t printed[PTR_CPU_LEVEL_COUNT];
    uint64_t nan_payloads[PTR_CPU_LEVEL_COUNT]; /* outputs NaN in both, with other bits */
    CheckedCallStatus status[PTR_CPU_LEVEL_COUNT];
} ConvTally;

/* Compares a level's frame with the reference's; prints the first few
 * differences. */
static void compare(const Layer *l, const float *ref, const float *got, const char *name,
                    int level, uint64_t layer_index, ConvTally *t)
{
    size_t count = frame_count(l);
    int differ = 0, border = 0;
    for (size_t i = 0; i < count; i++) {
        uint32_t want = to_bits(ref[i]), have = to_bits(got[i]);
        if (want == have)
            continue;
        /* Which of several NaN operands a fused multiply-add passes on is
         * the CPU's choice (and libm's, for the reference), not the
         * arithmetic's: both NaN is the same output. Not the guard, a
         * signalling NaN, which no arithmetic makes. */
        if (is_interior(l, i) && is_quiet_nan(want) && is_quiet_nan(have)) {
            t->nan_payloads[level]++;
            continue;
        }
        if (is_interior(l, i))
            differ = 1;
        else
            border = 1;
        if (t->printed[level]++ < 5)
            fprintf(stderr,
                    "%s differs from c on layer %" PRIu64 " (%zux%zu, %zu -> %zu channels, "
                    "relu %d, %s values) at float %zu%s: c %a (0x%08" PRIx32 "), %s %a (0x%08" PRIx32 ")\n",
                    name, layer_index, l->width, l->rows, l->in_channels, l->out_channels, l->relu,
                    values_names[l->kind], i, is_interior(l, i) ? "" : " (a guard)", ref[i], want,
                    name, got[i], have);
    }
    t->differ[level] += differ;
    t->border[level] += border;
}

int check_conv3x3(uint64_t seed, int *passed)
{
    PtrConvTable tables[PTR_CPU_LEVEL_COUNT];
    ConvTally tally = { 0 };
    PtrCpuLevel top = ptr_cpu_level();
    int kernels = 0;
    for (int level = PTR_CPU_SSE41; level <= (int)top; level++) {
        ptr_conv_init_level(&tables[level], (PtrCpuLevel)level);
        tally.status[level].check_xinuse = xinuse_supported();
        kernels += tables[level].conv3x3 != ptr_conv3x3_c;
    }
    if (!kernels) {
        printf("conv3x3: no assembly kernel at CPU level %s\n", ptr_cpu_level_name(top));
        return 0;
    }
    PtrRng rng = ptr_rng_for_sample(seed, 0, 33);
    for (uint64_t n = 0; n < LAYERS; n++) {
        Layer l;
        make_layer(&l, &rng);
        float *ref = guarded_frame(&l);
        ptr_conv3x3_c(frame_dst(&l, ref), l.src, l.weights, l.bias, l.width, l.rows,
                      l.in_channels, l.out_channels, l.relu);
        for (int level = PTR_CPU_SSE41; level <= (int)top; level++) {
            if (tables[level].conv3x3 == ptr_conv3x3_c)
                continue;
            float *got = guarded_frame(&l);
            ConvCall call = { frame_dst(&l, got), l.src, l.weights, l.bias, l.width, l.rows,
                              l.in_channels, l.out_channels, l.relu };
            ptr_checked_call_conv3x3(tables[level].conv3x3, &call, &tally.status[level]);
            compare(&l, ref, got, tables[level].name, level, n, &tally);
            free(got);
        }
        free(ref);
        free_layer(&l);
    }
    int failed = 0;
    for (int level = PTR_CPU_SSE41; level <= (int)top; level++) {
        if (tables[level].conv3x3 == ptr_conv3x3_c)
            continue;
        const CheckedCallStatus *s = &tally.status[level];
        printf("conv3x3 %-7s %d layers: %" PRIu64 " differ from c, %" PRIu64
               " wrote outside the output", tables[level].name, LAYERS, tally.differ[level],
               tally.border[level]);
        if (tally.nan_payloads[level])
            printf(" (%" PRIu64 " outputs NaN with another payload)", tally.nan_payloads[level]);
        print_status(s);
        if (tally.differ[level] || tally.border[level] || s->failures)
            failed++;
        else
            (*passed)++;
    }
    return failed;
}
