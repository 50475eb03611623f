/* The build's binning (accel/bvh_split.h's BvhBinFn, chosen by
 * bvh_bin_for_level): every level's against bvh_bin_c, bit for bit in every
 * lane a build reads, on ranges of 0 to 2,000 prims with 4 to 32 bins,
 * random ones and adversarial ones: every prim at one centre (one bin's
 * chain of maxima), centres on the bins' edges, signed zeros with extents
 * of 0, corners exactly 0 (a centre equal to its extent or to minus it),
 * coordinates near FLT_MAX (whose doubled centres overflow to infinity), a
 * few centres repeated, and bins over a box the prims are not in. The bins
 * past the candidate's count hold a guard that must survive. The kernel is
 * C built for AVX2, so no checked call: its calls keep the ABI as the
 * compiler makes them. */
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "accel/bvh_split.h"
#include "checkasm.h"

enum { RANGES = 3000, PRIMS_MAX = 2000 };

typedef enum Kind {
    KIND_RANDOM,
    KIND_ONE_CENTRE,
    KIND_EDGES,
    KIND_ZEROS,
    KIND_ZERO_CORNERS,
    KIND_HUGE,
    KIND_REPEATED,
    KIND_OUTSIDE,
    KIND_COUNT,
} Kind;

static const char *const kind_names[KIND_COUNT] = {
    "random", "one centre", "edges", "zeros", "zero corners", "huge", "repeated", "outside",
};

static const uint32_t guard_bits = 0x7fbadbadu; /* a signalling NaN */

/* A range's prims and the candidate that bins them: its box is the
 * prims' centres' (the build's is the padded boxes', which moves only the
 * bins' edges) but for KIND_OUTSIDE. */
static void make_range(Kind kind, PtrRng *rng, BvhPrim *prims, size_t *count, float *magnitude,
                       BvhCandidate *c)
{
    const size_t n = ptr_rng_next(rng) % (PRIMS_MAX + 1);
    const float scale = kind == KIND_HUGE ? 3e38f : powf(10.0f, uniform(rng, -3.0f, 6.0f));
    float repeated[4][3];
    for (int j = 0; j < 4; j++)
        for (int a = 0; a < 3; a++)
            repeated[j][a] = uniform(rng, -scale, scale);
    c->bins = 4 + (int)(ptr_rng_next(rng) % (BVH_BINS - 3));
    float lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
    *magnitude = kind == KIND_ZEROS ? 0.0f : scale;
    for (size_t i = 0; i < n; i++) {
        BvhPrim *p = &prims[i];
        float radius = kind == KIND_ZEROS ? 0.0f : scale * uniform(rng, 0.0f, 0.01f);
        for (int a = 0; a < 3; a++) {
            float x = uniform(rng, -scale, scale);
            switch (kind) {
            case KIND_ONE_CENTRE: x = repeated[0][a]; break;
            case KIND_REPEATED: x = repeated[ptr_rng_next(rng) % 4][a]; break;
            case KIND_ZEROS: x = ptr_rng_next(rng) & 1 ? -0.0f : 0.0f; break;
            case KIND_ZERO_CORNERS: {
                const float extent = bvh_prim_extent(&(BvhPrim){ .radius = radius }, *magnitude);
                const uint64_t corner = ptr_rng_next(rng) % 3;
                x = corner == 0 ? extent : corner == 1 ? -extent : x;
                break;
            }
            case KIND_EDGES: /* on the edges of bins over [-scale, scale] */
                x = -scale + 2.0f * scale * (float)(ptr_rng_next(rng) % (c->bins + 1)) /
                                 (float)c->bins;
                break;
            default: break;
            }
            p->centre[a] = x;
            lo[a] = ptr_minf(lo[a], x);
            hi[a] = ptr_maxf(hi[a], x);
        }
        p->radius = radius;
        p->rest = ptr_rng_next(rng);
    }
    if (kind == KIND_OUTSIDE || n == 0)
        for (int a = 0; a < 3; a++) {
            lo[a] = uniform(rng, -scale, 0.0f);
            hi[a] = lo[a] + uniform(rng, 0.0f, scale);
        }
    for (int a = 0; a < 3; a++) {
        /* bvh_candidate_init's base and scale over the box. */
        const float extent = 2.0f * (hi[a] - lo[a]);
        c->bin_base[a] = 2.0f * lo[a];
        c->bin_scale[a] = extent > 0.0f ? (float)c->bins * 0.99999f / extent : 0.0f;
    }
    *count = n;
}

static void guard(BvhBins *bins)
{
    for (size_t i = 0; i < sizeof bins->box / sizeof(float); i++)
        memcpy(&bins->box[0][0][0] + i, &guard_bits, sizeof guard_bits);
}

/* Whether got's bins have ref's bits in every lane read (all but lane 3),
 * and the guard past the candidate's bins. */
static int same_bins(const BvhBins *ref, const BvhBins *got, int bin_count)
{
    for (int a = 0; a < 3; a++)
        for (int k = 0; k < BVH_BINS; k++)
            for (int lane = 0; lane < 8; lane++) {
                if (k < bin_count && lane == 3)
                    continue;
                if (memcmp(&ref->box[a][k][lane], &got->box[a][k][lane], sizeof(float)))
                    return 0;
            }
    return 1;
}

int check_bvh_bin(uint64_t seed, int *passed)
{
    const PtrCpuLevel top = ptr_cpu_level();
    BvhBinKernel kernels[PTR_CPU_LEVEL_COUNT];
    uint64_t differ[PTR_CPU_LEVEL_COUNT][KIND_COUNT] = { { 0 } };
    /* The levels checked: those whose kernel is neither c nor the one
     * below's. */
    int checked[PTR_CPU_LEVEL_COUNT] = { 0 }, any = 0;
    for (int l = PTR_CPU_NONE; l <= (int)top; l++) {
        kernels[l] = bvh_bin_for_level((PtrCpuLevel)l);
        checked[l] = kernels[l].bin != bvh_bin_c &&
                     (l == PTR_CPU_NONE || kernels[l].bin != kernels[l - 1].bin);
        any |= checked[l];
    }
    if (!any) {
        printf("bvh_bin: no kernel but c at CPU level %s\n", ptr_cpu_level_name(top));
        return 0;
    }
    static BvhPrim prims[PRIMS_MAX];
    static BvhBins ref, got;
    PtrRng rng = ptr_rng_for_sample(seed, 0, 34);
    for (int r = 0; r < RANGES; r++) {
        const Kind kind = (Kind)(r % KIND_COUNT);
        BvhCandidate c;
        size_t count;
        float magnitude;
        make_range(kind, &rng, prims, &count, &magnitude, &c);
        guard(&ref);
        bvh_bins_clear(&c, &ref);
        bvh_bin_c(prims, count, magnitude, &c, &ref);
        for (int l = PTR_CPU_SSE41; l <= (int)top; l++) {
            if (!checked[l])
                continue;
            guard(&got);
            bvh_bins_clear(&c, &got);
            kernels[l].bin(prims, count, magnitude, &c, &got);
            if (!same_bins(&ref, &got, c.bins) && differ[l][kind]++ == 0)
                printf("bvh_bin %s: %s range %d (%zu prims, %d bins) differs from c\n",
                       kernels[l].name, kind_names[kind], r, count, c.bins);
        }
    }
    int failed = 0;
    for (int l = PTR_CPU_SSE41; l <= (int)top; l++) {
        if (!checked[l])
            continue;
        uint64_t total = 0;
        for (int k = 0; k < KIND_COUNT; k++)
            total += differ[l][k];
        printf("bvh_bin %-7s %d ranges: %" PRIu64 " differ from c\n", kernels[l].name, RANGES,
               total);
        total ? failed++ : (*passed)++;
    }
    return failed;
}
