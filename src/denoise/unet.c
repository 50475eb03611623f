#include "denoise/unet.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/threads.h"
#include "denoise/tza.h"

/* An architecture: its convolutions' names in the order they run, and how
 * many run at each encoder level before its pooling, at the bottom, and at
 * each decoder level after its upsampling (OIDN's training/model.py). */
typedef struct Architecture {
    const char *names[PTR_UNET_MAX_CONVS];
    int encoder[4], bottom, decoder[4]; /* decoder[k]: level k, run from 3 to 0 */
} Architecture;

static const Architecture unet_base = {
    { "enc_conv0", "enc_conv1", "enc_conv2", "enc_conv3", "enc_conv4", "enc_conv5a",
      "enc_conv5b", "dec_conv4a", "dec_conv4b", "dec_conv3a", "dec_conv3b", "dec_conv2a",
      "dec_conv2b", "dec_conv1a", "dec_conv1b", "dec_conv0" },
    { 2, 1, 1, 1 }, 2, { 3, 2, 2, 2 },
};

static const Architecture unet_large = {
    { "enc_conv1a", "enc_conv1b", "enc_conv2a", "enc_conv2b", "enc_conv3a", "enc_conv3b",
      "enc_conv4a", "enc_conv4b", "enc_conv5a", "enc_conv5b", "dec_conv4a", "dec_conv4b",
      "dec_conv3a", "dec_conv3b", "dec_conv2a", "dec_conv2b", "dec_conv1a", "dec_conv1b",
      "dec_conv1c" },
    { 2, 2, 2, 2 }, 2, { 3, 2, 2, 2 },
};

static size_t padded(size_t channels)
{
    return (channels + PTR_CONV_BLOCK - 1) / PTR_CONV_BLOCK * PTR_CONV_BLOCK;
}

/* A zeroed block of floats, 64-byte aligned, or NULL. */
static float *zeroed_floats(size_t count)
{
    size_t bytes = (count * sizeof(float) + 63) / 64 * 64;
    float *p = aligned_alloc(64, bytes ? bytes : 64);
    if (p)
        memset(p, 0, bytes);
    return p;
}

/* A map of the set: its floats, their count, and whether it is taken. */
typedef struct Map {
    float *floats;
    size_t count;
    int taken;
} Map;

struct PtrUnetMaps {
    Map *map;
    size_t count, room;
};

PtrUnetMaps *ptr_unet_maps_new(void)
{
    return calloc(1, sizeof(PtrUnetMaps));
}

void ptr_unet_maps_free(PtrUnetMaps *maps)
{
    if (!maps)
        return;
    for (size_t i = 0; i < maps->count; i++)
        free(maps->map[i].floats);
    free(maps->map);
    free(maps);
}

/* Zeroes the border of a map of width x height pixels of channels. */
static void zero_border(float *map, size_t width, size_t height, size_t channels)
{
    const size_t row = (width + 2) * channels;
    memset(map, 0, row * sizeof *map);
    memset(map + (height + 1) * row, 0, row * sizeof *map);
    for (size_t y = 1; y <= height; y++) {
        memset(map + y * row, 0, channels * sizeof *map);
        memset(map + y * row + (width + 1) * channels, 0, channels * sizeof *map);
    }
}

float *ptr_unet_map_take(PtrUnetMaps *maps, size_t width, size_t height, size_t channels)
{
    const size_t count = (width + 2) * (height + 2) * channels;
    Map *best = NULL, *largest = NULL; /* of the free maps: the least that fits, the largest */
    for (size_t i = 0; i < maps->count; i++) {
        Map *m = &maps->map[i];
        if (m->taken)
            continue;
        if (m->count >= count && (!best || m->count < best->count))
            best = m;
        if (!largest || m->count > largest->count)
            largest = m;
    }
    if (!best) {
        /* None fits: the largest free map gives way to a larger one, so that
         * the set holds no more maps than a tile has at once. */
        if (largest) {
            free(largest->floats);
            *largest = maps->map[--maps->count];
        }
        if (maps->count == maps->room) {
            const size_t room = maps->room ? 2 * maps->room : 16;
            Map *grown = realloc(maps->map, room * sizeof *grown);
            if (!grown)
                return NULL;
            maps->map = grown;
            maps->room = room;
        }
        const size_t bytes = (count * sizeof(float) + 63) / 64 * 64;
        float *floats = aligned_alloc(64, bytes ? bytes : 64);
        if (!floats)
            return NULL;
        best = &maps->map[maps->count++];
        *best = (Map){ floats, count, 0 };
    }
    best->taken = 1;
    zero_border(best->floats, width, height, channels);
    return best->floats;
}

void ptr_unet_map_give(PtrUnetMaps *maps, float *map)
{
    for (size_t i = 0; map && i < maps->count; i++)
        if (maps->map[i].floats == map)
            maps->map[i].taken = 0;
}

/* The archive and where the build has come to: the channels of the map the
 * next convolution reads, the real ones and their padded count. */
typedef struct Builder {
    const char *path;
    const PtrTensorArchive *archive;
    const Architecture *arch;
    PtrUnet *unet;
    size_t channels, padded_channels;
    size_t input_channels;
    size_t pooled[5]; /* the real channels of each pooled map */
} Builder;

/* Packs a convolution whose input is a channels (padded to a_padded)
 * followed by skip channels: the tensor's input channel i moves to where
 * the concatenated feature map holds it. */
static PtrResult pack(PtrUnetConv *conv, const PtrTensor *w, const PtrTensor *b, size_t a,
                      size_t a_padded, size_t skip, PtrError *err)
{
    size_t out = w->dims[0];
    conv->in = a_padded + padded(skip);
    conv->out = padded(out);
    float *spread = zeroed_floats(out * conv->in * 9);
    conv->weights = zeroed_floats(ptr_conv_weight_count(conv->in, conv->out));
    conv->bias = zeroed_floats(conv->out);
    if (!spread || !conv->weights || !conv->bias) {
        free(spread);
        return ptr_error_set(err, PTR_ERR_NOMEM, "out of memory for the denoiser's weights");
    }
    for (size_t o = 0; o < out; o++)
        for (size_t i = 0; i < a + skip; i++)
            memcpy(&spread[(o * conv->in + (i < a ? i : a_padded + i - a)) * 9],
                   &w->data[(o * (a + skip) + i) * 9], 9 * sizeof(float));
    ptr_conv_pack(conv->weights, spread, conv->in, out, conv->in, conv->out);
    memcpy(conv->bias, b->data, out * sizeof(float));
    free(spread);
    return PTR_OK;
}

/* Adds the next convolution, running at level, its input joined by pooled
 * map number concat (0: the input; -1: none): its tensors found and their
 * shapes checked against the channels the layers before it make. */
static PtrResult add(Builder *b, int level, int concat, PtrError *err)
{
    int l = b->unet->count;
    const char *name = b->arch->names[l];
    char key[64];
    snprintf(key, sizeof key, "%s.weight", name);
    const PtrTensor *w = ptr_tza_find(b->archive, key);
    snprintf(key, sizeof key, "%s.bias", name);
    const PtrTensor *bias = ptr_tza_find(b->archive, key);
    if (!w || !bias)
        return ptr_error_set(err, PTR_ERR_INSTALL, "%s: no tensor %s.%s: not a U-Net's weights",
                             b->path, name, w ? "bias" : "weight");
    size_t skip = concat < 0 ? 0 : concat == 0 ? b->input_channels : b->pooled[concat];
    int last = l == PTR_UNET_MAX_CONVS - 1 || !b->arch->names[l + 1];
    if (w->ndims != 4 || strcmp(w->layout, "oihw") || w->dims[2] != 3 || w->dims[3] != 3 ||
        w->dims[1] != b->channels + skip || (last && w->dims[0] != PTR_UNET_OUTPUT_CHANNELS))
        return ptr_error_set(err, PTR_ERR_INSTALL,
                             "%s: tensor %s.weight is not a 3x3 convolution (oihw) of %zu input "
                             "channels%s, as the network's layers before it make it",
                             b->path, name, b->channels + skip, last ? " to 3 outputs" : "");
    if (bias->ndims != 1 || bias->dims[0] != w->dims[0])
        return ptr_error_set(err, PTR_ERR_INSTALL, "%s: tensor %s.bias does not have %u values",
                             b->path, name, (unsigned)w->dims[0]);
    PtrUnetConv *conv = &b->unet->conv[l];
    conv->level = level;
    conv->concat = concat;
    conv->concat_channels = concat < 0 ? 0 : padded(skip);
    PtrResult res = pack(conv, w, bias, b->channels, b->padded_channels, skip, err);
    if (res != PTR_OK)
        return res;
    b->unet->count++;
    b->channels = w->dims[0];
    b->padded_channels = conv->out;
    return PTR_OK;
}

static PtrResult build(Builder *b, PtrError *err)
{
    PtrResult res = PTR_OK;
    for (int k = 0; k < 4; k++) {
        for (int i = 0; res == PTR_OK && i < b->arch->encoder[k]; i++)
            res = add(b, k, -1, err);
        if (res != PTR_OK)
            return res;
        b->unet->conv[b->unet->count - 1].pool = k + 1;
        b->pooled[k + 1] = b->channels;
    }
    for (int i = 0; res == PTR_OK && i < b->arch->bottom; i++)
        res = add(b, 4, -1, err);
    for (int k = 3; k >= 0; k--)
        for (int i = 0; res == PTR_OK && i < b->arch->decoder[k]; i++)
            res = add(b, k, i == 0 ? k : -1, err);
    return res;
}

PtrResult ptr_unet_load(const char *path, size_t input_channels, PtrCpuLevel level,
                        PtrUnet **out, PtrError *err)
{
    PtrTensorArchive *archive;
    PtrResult res = ptr_tza_read(path, &archive, err);
    if (res != PTR_OK)
        return res;
    PtrUnet *unet = calloc(1, sizeof *unet);
    if (unet) {
        Builder b = { path, archive,
                      ptr_tza_find(archive, "enc_conv1b.weight") ? &unet_large : &unet_base,
                      unet, input_channels, padded(input_channels), input_channels, { 0 } };
        res = build(&b, err);
    } else {
        res = ptr_error_set(err, PTR_ERR_NOMEM, "out of memory for the denoiser");
    }
    ptr_tza_free(archive);
    if (res != PTR_OK) {
        ptr_unet_free(unet);
        return res;
    }
    ptr_conv_init_level(&unet->table, level);
    *out = unet;
    return PTR_OK;
}

/* A range of pixels of one row of a map, lo .. hi (empty: lo > hi). */
typedef struct Range {
    long lo, hi;
} Range;

static void widen(Range *s, Range by)
{
    s->lo = by.lo < s->lo ? by.lo : s->lo;
    s->hi = by.hi > s->hi ? by.hi : s->hi;
}

/* The input pixels of a row that output pixel p depends on: the network
 * walked from its last convolution back, each step's needs in the map it
 * reads. p must be large enough that no range goes below 0: halving with
 * `/` rounds towards zero, which is the floor only for what is not
 * negative. */
static Range input_range(const PtrUnet *unet, long p)
{
    Range need = { p, p }, pooled[5]; /* pooled[k]: of the map pooled to level k; 0: the input */
    for (int k = 0; k < 5; k++)
        pooled[k] = (Range){ LONG_MAX, LONG_MIN };
    for (int l = unet->count - 1; l >= 0; l--) {
        const PtrUnetConv *c = &unet->conv[l];
        need.lo--, need.hi++; /* a 3x3 convolution, in its level's pixels */
        if (c->concat >= 0) { /* reads the map before it, upsampled, and a pooled one */
            widen(&pooled[c->concat], need);
            need = (Range){ need.lo / 2, need.hi / 2 };
        } else if (l > 0 && unet->conv[l - 1].pool) { /* reads the map before it pooled */
            Range *in = &pooled[unet->conv[l - 1].pool];
            widen(in, need);
            need = (Range){ 2 * in->lo, 2 * in->hi + 1 };
        }
    }
    widen(&pooled[0], need);
    return pooled[0];
}

size_t ptr_unet_overlap(const PtrUnet *unet)
{
    /* Both sides of an edge at 1024, on the grid: the first pixel kept
     * after it and the last before it. */
    const long edge = 1024;
    const long before = edge - input_range(unet, edge).lo,
               after = input_range(unet, edge - 1).hi - (edge - 1);
    const size_t reach = (size_t)(before > after ? before : after);
    return ptr_unet_align(reach);
}

void ptr_unet_free(PtrUnet *unet)
{
    if (!unet)
        return;
    for (int l = 0; l < PTR_UNET_MAX_CONVS; l++) { /* a failed build's last too */
        free(unet->conv[l].weights);
        free(unet->conv[l].bias);
    }
    free(unet);
}

void ptr_unet_pool(float *dst, const float *src, size_t width, size_t channels, size_t y0,
                   size_t y1)
{
    size_t src_row = (2 * width + 2) * channels, dst_row = (width + 2) * channels;
    for (size_t y = y0; y < y1; y++) {
        const float *top = src + (2 * y + 1) * src_row + channels;
        float *out = dst + (y + 1) * dst_row + channels;
        for (size_t x = 0; x < width; x++)
            for (size_t c = 0; c < channels; c++) {
                const float *p = top + 2 * x * channels + c;
                float m = p[0];
                m = p[channels] > m ? p[channels] : m;
                m = p[src_row] > m ? p[src_row] : m;
                m = p[src_row + channels] > m ? p[src_row + channels] : m;
                out[x * channels + c] = m;
            }
    }
}

void ptr_unet_upsample_concat(float *dst, const float *up, size_t up_channels, const float *skip,
                              size_t skip_channels, size_t width, size_t y0, size_t y1)
{
    size_t channels = up_channels + skip_channels;
    for (size_t y = y0; y < y1; y++) {
        float *out = dst + ((y + 1) * (width + 2) + 1) * channels;
        const float *from_up = up + ((y / 2 + 1) * (width / 2 + 2) + 1) * up_channels;
        const float *from_skip = skip + ((y + 1) * (width + 2) + 1) * skip_channels;
        for (size_t x = 0; x < width; x++) {
            memcpy(out + x * channels, from_up + x / 2 * up_channels,
                   up_channels * sizeof(float));
            memcpy(out + x * channels + up_channels, from_skip + x * skip_channels,
                   skip_channels * sizeof(float));
        }
    }
}

/* One step of the network on a piece of rows, for ptr_parallel_ranges. */
typedef struct Step {
    const PtrUnet *unet;
    const PtrUnetConv *conv; /* or NULL: a resampling */
    float *dst;
    const float *src, *skip;
    size_t width, src_channels, skip_channels;
    int relu;
} Step;

static void run_conv_rows(void *arg, size_t y0, size_t y1)
{
    const Step *s = arg;
    size_t in = s->conv->in, out = s->conv->out;
    if (y0 == y1) /* more threads than rows: the kernels are not asked for none */
        return;
    s->unet->table.conv3x3(s->dst + ((y0 + 1) * (s->width + 2) + 1) * out,
                           s->src + y0 * (s->width + 2) * in, s->conv->weights, s->conv->bias,
                           s->width, y1 - y0, in, out, s->relu);
}

static void run_pool_rows(void *arg, size_t y0, size_t y1)
{
    const Step *s = arg;
    ptr_unet_pool(s->dst, s->src, s->width, s->src_channels, y0, y1);
}

static void run_upsample_rows(void *arg, size_t y0, size_t y1)
{
    const Step *s = arg;
    ptr_unet_upsample_concat(s->dst, s->src, s->src_channels, s->skip, s->skip_channels,
                             s->width, y0, y1);
}

/* What the steps of one tile's run share. */
typedef struct Run {
    const PtrUnet *unet;
    PtrUnetMaps *maps;
    int threads;
    PtrError *err;
} Run;

/* A map of width x height x channels, its border zero, or NULL (with the
 * error set) when memory runs out. */
static float *take_map(Run *run, size_t width, size_t height, size_t channels)
{
    float *map = ptr_unet_map_take(run->maps, width, height, channels);
    if (!map)
        ptr_error_set(run->err, PTR_ERR_NOMEM,
                      "out of memory for the denoiser's feature maps (%zux%zu pixels)", width,
                      height);
    return map;
}

/* Convolution l on src (width x height), into a new map (or into dst when
 * given); NULL when memory runs out. */
static float *conv(Run *run, int l, const float *src, size_t width, size_t height, float *dst)
{
    const PtrUnetConv *c = &run->unet->conv[l];
    float *out = dst ? dst : take_map(run, width, height, c->out);
    if (!out)
        return NULL;
    Step s = { run->unet, c, out, src, NULL, width, 0, 0, l != run->unet->count - 1 };
    ptr_parallel_ranges(run->threads, 0, height, run_conv_rows, &s);
    return out;
}

/* 2x2 max-pooling of src (width x height, channels channels). */
static float *pool(Run *run, const float *src, size_t channels, size_t width, size_t height)
{
    float *out = take_map(run, width / 2, height / 2, channels);
    if (!out)
        return NULL;
    Step s = { run->unet, NULL, out, src, NULL, width / 2, channels, 0, 0 };
    ptr_parallel_ranges(run->threads, 0, height / 2, run_pool_rows, &s);
    return out;
}

/* src (width/2 x height/2, channels channels) upsampled and followed by
 * skip's skip_channels. */
static float *upsample_concat(Run *run, const float *src, size_t channels, const float *skip,
                              size_t skip_channels, size_t width, size_t height)
{
    float *out = take_map(run, width, height, channels + skip_channels);
    if (!out)
        return NULL;
    Step s = { run->unet, NULL, out, src, skip, width, channels, skip_channels, 0 };
    ptr_parallel_ranges(run->threads, 0, height, run_upsample_rows, &s);
    return out;
}

PtrResult ptr_unet_run(const PtrUnet *unet, PtrUnetMaps *maps, const float *input, size_t width,
                       size_t height, int threads, float *output, PtrError *err)
{
    Run run = { unet, maps, threads, err };
    /* pools[k], k = 1 to 4: the map pooled to level k, kept for the decoder;
     * src: the map the next step reads, which owned holds when it is not
     * the input, a pooled map or the output. */
    float *pools[5] = { NULL }, *owned = NULL;
    const float *src = input;
    for (int l = 0; l < unet->count; l++) {
        const PtrUnetConv *c = &unet->conv[l];
        size_t w = width >> c->level, h = height >> c->level;
        int last = l == unet->count - 1;
        if (c->concat >= 0) {
            float *joined = upsample_concat(&run, src, unet->conv[l - 1].out,
                                            c->concat ? pools[c->concat] : input,
                                            c->concat_channels, w, h);
            ptr_unet_map_give(maps, owned);
            src = owned = joined;
            if (!joined)
                break;
        }
        float *out = conv(&run, l, src, w, h, last ? output : NULL);
        ptr_unet_map_give(maps, owned);
        owned = last ? NULL : out;
        if (!(src = out))
            break;
        if (c->pool) {
            pools[c->pool] = pool(&run, src, c->out, w, h);
            ptr_unet_map_give(maps, owned);
            owned = NULL;
            if (!(src = pools[c->pool]))
                break;
        }
    }
    ptr_unet_map_give(maps, owned);
    for (int k = 1; k <= 4; k++)
        ptr_unet_map_give(maps, pools[k]);
    return src == output ? PTR_OK : PTR_ERR_NOMEM;
}
