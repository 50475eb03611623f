#include "denoise/unet.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/threads.h"
#include "denoise/tza.h"

/* Where a convolution's input comes from, besides the previous layer's
 * output: the feature map concatenated after it (OIDN's training/model.py). */
enum { NO_SKIP = -1, SKIP_INPUT = -2 };

static const struct {
    const char *name;
    int skip; /* the layer whose output, pooled, is concatenated; or the above */
} layers[PTR_UNET_CONVS] = {
    { "enc_conv0", NO_SKIP },  { "enc_conv1", NO_SKIP },  { "enc_conv2", NO_SKIP },
    { "enc_conv3", NO_SKIP },  { "enc_conv4", NO_SKIP },  { "enc_conv5a", NO_SKIP },
    { "enc_conv5b", NO_SKIP }, { "dec_conv4a", PTR_UNET_ENC_CONV3 },
    { "dec_conv4b", NO_SKIP }, { "dec_conv3a", PTR_UNET_ENC_CONV2 },
    { "dec_conv3b", NO_SKIP }, { "dec_conv2a", PTR_UNET_ENC_CONV1 },
    { "dec_conv2b", NO_SKIP }, { "dec_conv1a", SKIP_INPUT },
    { "dec_conv1b", NO_SKIP }, { "dec_conv0", NO_SKIP },
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

/* The weight tensor of layer index and its bias, checked against the input
 * channels the U-Net feeds it (in) and, for the last, its output. */
static PtrResult find_layer(const char *path, const PtrTensorArchive *archive, int index,
                            size_t in, const PtrTensor **weight, const PtrTensor **bias,
                            PtrError *err)
{
    char name[64];
    snprintf(name, sizeof name, "%s.weight", layers[index].name);
    *weight = ptr_tza_find(archive, name);
    snprintf(name, sizeof name, "%s.bias", layers[index].name);
    *bias = ptr_tza_find(archive, name);
    const PtrTensor *w = *weight, *b = *bias;
    if (!w || !b)
        return ptr_error_set(err, PTR_ERR_INSTALL, "%s: no tensor %s.%s: not a U-Net's weights",
                             path, layers[index].name, w ? "bias" : "weight");
    if (w->ndims != 4 || strcmp(w->layout, "oihw") || w->dims[2] != 3 || w->dims[3] != 3 ||
        w->dims[1] != in ||
        (index == PTR_UNET_DEC_CONV0 && w->dims[0] != PTR_UNET_OUTPUT_CHANNELS))
        return ptr_error_set(err, PTR_ERR_INSTALL,
                             "%s: tensor %s.weight is not a 3x3 convolution (oihw) of %zu input "
                             "channels%s, as the U-Net's layers before it make it",
                             path, layers[index].name, in,
                             index == PTR_UNET_DEC_CONV0 ? " to 3 outputs" : "");
    if (b->ndims != 1 || b->dims[0] != w->dims[0])
        return ptr_error_set(err, PTR_ERR_INSTALL, "%s: tensor %s.bias does not have %u values",
                             path, layers[index].name, (unsigned)w->dims[0]);
    return PTR_OK;
}

/* Packs a layer whose input is a channels (padded to a_padded) followed by
 * skip channels: the tensor's input channel i moves to where the
 * concatenated feature map holds it. */
static PtrResult pack_layer(PtrUnetConv *conv, const PtrTensor *w, const PtrTensor *b, size_t a,
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

static PtrResult build(const char *path, const PtrTensorArchive *archive, PtrUnet *unet,
                       PtrError *err)
{
    size_t real_out[PTR_UNET_CONVS];
    for (int l = 0; l < PTR_UNET_CONVS; l++) {
        size_t a = l == 0 ? PTR_UNET_INPUT_CHANNELS : real_out[l - 1];
        size_t a_padded = l == 0 ? PTR_CONV_BLOCK : unet->conv[l - 1].out;
        int s = layers[l].skip;
        size_t skip = s == NO_SKIP      ? 0
                      : s == SKIP_INPUT ? PTR_UNET_INPUT_CHANNELS
                                        : real_out[s];
        const PtrTensor *w, *b;
        PtrResult res = find_layer(path, archive, l, a + skip, &w, &b, err);
        if (res == PTR_OK)
            res = pack_layer(&unet->conv[l], w, b, a, a_padded, skip, err);
        if (res != PTR_OK)
            return res;
        real_out[l] = w->dims[0];
    }
    return PTR_OK;
}

PtrResult ptr_unet_load(const char *path, PtrCpuLevel level, PtrUnet **out, PtrError *err)
{
    PtrTensorArchive *archive;
    PtrResult res = ptr_tza_read(path, &archive, err);
    if (res != PTR_OK)
        return res;
    PtrUnet *unet = calloc(1, sizeof *unet);
    res = unet ? build(path, archive, unet, err)
               : ptr_error_set(err, PTR_ERR_NOMEM, "out of memory for the denoiser");
    ptr_tza_free(archive);
    if (res != PTR_OK) {
        ptr_unet_free(unet);
        return res;
    }
    ptr_conv_init_level(&unet->table, level);
    *out = unet;
    return PTR_OK;
}

void ptr_unet_free(PtrUnet *unet)
{
    if (!unet)
        return;
    for (int l = 0; l < PTR_UNET_CONVS; l++) {
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

/* The run of one tile: the feature maps alive, freed as soon as unused. */
typedef struct Run {
    const PtrUnet *unet;
    int threads;
    PtrError *err;
} Run;

/* A new zeroed map of width x height x channels into *out, or NULL (with the
 * error set) when memory runs out. */
static float *new_map(Run *run, size_t width, size_t height, size_t channels)
{
    float *map = zeroed_floats(ptr_unet_map_floats(width, height, channels));
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
    float *out = dst ? dst : new_map(run, width, height, c->out);
    if (!out)
        return NULL;
    Step s = { run->unet, c, out, src, NULL, width, 0, 0, l != PTR_UNET_DEC_CONV0 };
    ptr_parallel_ranges(run->threads, 0, height, run_conv_rows, &s);
    return out;
}

/* 2x2 max-pooling of src (width x height, the output of conv l). */
static float *pool(Run *run, int l, const float *src, size_t width, size_t height)
{
    size_t channels = run->unet->conv[l].out;
    float *out = new_map(run, width / 2, height / 2, channels);
    if (!out)
        return NULL;
    Step s = { run->unet, NULL, out, src, NULL, width / 2, channels, 0, 0 };
    ptr_parallel_ranges(run->threads, 0, height / 2, run_pool_rows, &s);
    return out;
}

/* src (width/2 x height/2, the output of conv l) upsampled and followed by
 * skip's skip_channels. */
static float *upsample_concat(Run *run, int l, const float *src, const float *skip,
                              size_t skip_channels, size_t width, size_t height)
{
    size_t channels = run->unet->conv[l].out;
    float *out = new_map(run, width, height, channels + skip_channels);
    if (!out)
        return NULL;
    Step s = { run->unet, NULL, out, src, skip, width, channels, skip_channels, 0 };
    ptr_parallel_ranges(run->threads, 0, height, run_upsample_rows, &s);
    return out;
}

PtrResult ptr_unet_run(const PtrUnet *unet, const float *input, size_t width, size_t height,
                       int threads, float *output, PtrError *err)
{
    Run run = { unet, threads, err };
    size_t w[5], h[5]; /* the sizes of the five levels */
    for (int k = 0; k < 5; k++) {
        w[k] = width >> k;
        h[k] = height >> k;
    }
    /* pools[k]: the output of encoder convolution k (at level k - 1) pooled
     * to level k, kept for the decoder; x: the current map. */
    float *pools[5] = { NULL }, *x = NULL, *y = NULL;
#define STEP(expr)                                                                             \
    do {                                                                                       \
        float *next_ = (expr);                                                                 \
        free(x);                                                                               \
        x = next_;                                                                             \
        if (!x)                                                                                \
            goto fail;                                                                         \
    } while (0)
    STEP(conv(&run, PTR_UNET_ENC_CONV0, input, w[0], h[0], NULL));
    for (int k = 1; k <= 4; k++) {
        STEP(conv(&run, k, k == 1 ? x : pools[k - 1], w[k - 1], h[k - 1], NULL));
        if (!(pools[k] = pool(&run, k, x, w[k - 1], h[k - 1])))
            goto fail;
    }
    STEP(conv(&run, PTR_UNET_ENC_CONV5A, pools[4], w[4], h[4], NULL));
    STEP(conv(&run, PTR_UNET_ENC_CONV5B, x, w[4], h[4], NULL));
    /* Each level of the decoder: the map upsampled and joined by the
     * encoder's of that size (the input at the top), two convolutions. */
    for (int k = 3; k >= 0; k--) {
        int a = PTR_UNET_DEC_CONV4A + 2 * (3 - k);
        STEP(upsample_concat(&run, a - 1, x, k ? pools[k] : input,
                             k ? unet->conv[k].out : PTR_CONV_BLOCK, w[k], h[k]));
        STEP(conv(&run, a, x, w[k], h[k], NULL));
        STEP(conv(&run, a + 1, x, w[k], h[k], NULL));
    }
#undef STEP
    y = conv(&run, PTR_UNET_DEC_CONV0, x, w[0], h[0], output);
fail:
    free(x);
    for (int k = 1; k <= 4; k++)
        free(pools[k]);
    return y ? PTR_OK : PTR_ERR_NOMEM;
}
