#include "denoise/denoise.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "base/module.h"
#include "base/threads.h"
#include "denoise/transfer.h"
#include "denoise/unet.h"

/* The network that denoises the colour; for high quality, also those that
 * filter the albedo and the normal first (otherwise NULL). */
struct PtrDenoiser {
    PtrUnet *color, *albedo, *normal;
};

static const char *const quality_names[] = {
    [PTR_DENOISE_FAST] = "fast", [PTR_DENOISE_BALANCED] = "balanced", [PTR_DENOISE_HIGH] = "high",
};

const char *ptr_denoise_quality_name(PtrDenoiseQuality quality)
{
    return quality_names[quality];
}

PtrResult ptr_denoise_quality_parse(const char *text, PtrDenoiseQuality *out, PtrError *err)
{
    for (int q = PTR_DENOISE_FAST; q <= PTR_DENOISE_HIGH; q++)
        if (!strcmp(text, quality_names[q])) {
            *out = (PtrDenoiseQuality)q;
            return PTR_OK;
        }
    return ptr_error_set(err, PTR_ERR_USAGE, "'%s' is not fast, balanced or high", text);
}

static int is_dir(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISDIR(st.st_mode);
}

/* The folder of the weights: weights_dir, else $PTR_WEIGHTS_DIR, else
 * share/ptr/weights beside the executable's bin/ (an installation moved
 * elsewhere), else under the prefix ptr was built for. */
static PtrResult weights_folder(const char *weights_dir, char *path, size_t size, PtrError *err)
{
    const char *env = getenv("PTR_WEIGHTS_DIR");
    const char *chosen = weights_dir ? weights_dir : env && *env ? env : NULL;
    if (!chosen) {
        if (ptr_module_path("../share/ptr/weights", "denoiser's weights", path, size, NULL) ==
                PTR_OK &&
            is_dir(path))
            return PTR_OK;
        chosen = PTR_INSTALL_PREFIX "/share/ptr/weights";
    }
    if ((size_t)snprintf(path, size, "%s", chosen) >= size)
        return ptr_error_set(err, PTR_ERR_INSTALL, "%s: path too long for the weights' folder",
                             chosen);
    return PTR_OK;
}

/* Loads the network of this file in folder into *out. */
static PtrResult load(const char *folder, const char *file, size_t input_channels,
                      PtrCpuLevel level, PtrUnet **out, PtrError *err)
{
    char path[4096 + 64];
    snprintf(path, sizeof path, "%s/%s", folder, file);
    return ptr_unet_load(path, input_channels, level, out, err);
}

PtrResult ptr_denoiser_new(PtrDenoiseQuality quality, const char *weights_dir,
                           PtrCpuLevel level, PtrDenoiser **out, PtrError *err)
{
    char folder[4096];
    PtrResult res = weights_folder(weights_dir, folder, sizeof folder, err);
    if (res != PTR_OK)
        return res;
    PtrDenoiser *d = calloc(1, sizeof *d);
    if (!d)
        return ptr_error_set(err, PTR_ERR_NOMEM, "out of memory for the denoiser");
    if (quality == PTR_DENOISE_HIGH) {
        res = load(folder, "rt_alb_large.tza", 3, level, &d->albedo, err);
        if (res == PTR_OK)
            res = load(folder, "rt_nrm_large.tza", 3, level, &d->normal, err);
        if (res == PTR_OK)
            res = load(folder, "rt_hdr_calb_cnrm_large.tza", 9, level, &d->color, err);
    } else {
        res = load(folder,
                   quality == PTR_DENOISE_FAST ? "rt_hdr_alb_nrm_small.tza" : "rt_hdr_alb_nrm.tza",
                   9, level, &d->color, err);
    }
    if (res != PTR_OK) {
        ptr_denoiser_free(d);
        return res;
    }
    *out = d;
    return PTR_OK;
}

void ptr_denoiser_free(PtrDenoiser *denoiser)
{
    if (!denoiser)
        return;
    ptr_unet_free(denoiser->color);
    ptr_unet_free(denoiser->albedo);
    ptr_unet_free(denoiser->normal);
    free(denoiser);
}

/* One dimension's tiles: tile j reads the image from begin, size pixels
 * (padded to a multiple of 16 with zeros), and keeps out_begin .. out_end. */
typedef struct Span {
    size_t begin, size, out_begin, out_end;
} Span;

static size_t tile_count(size_t n, size_t tile, size_t overlap)
{
    size_t stride = tile - 2 * overlap;
    return ptr_unet_align(n) <= tile ? 1 : 1 + (n - tile + stride - 1) / stride;
}

static Span tile_span(size_t n, size_t tile, size_t overlap, size_t count, size_t j)
{
    if (count == 1)
        return (Span){ 0, n, 0, n };
    size_t begin = j * (tile - 2 * overlap);
    Span s = { begin, n - begin < tile ? n - begin : tile, begin + overlap,
               begin + tile - overlap };
    if (j == 0)
        s.out_begin = 0;
    if (j == count - 1)
        s.out_end = n;
    return s;
}

/* What a network takes and gives: the colour guided by albedo and normal,
 * or one guide alone. */
typedef enum Mode { MODE_COLOR, MODE_ALBEDO, MODE_NORMAL } Mode;

/* A tile's work beyond the network, row by row, for ptr_parallel_ranges. */
typedef struct TileJob {
    const PtrDenoiseInput *input;
    Mode mode;
    PtrTransfer transfer;
    Span x, y;
    size_t map_width; /* the tile's padded width */
    float *map;       /* the network's input, or its output */
    float *result;    /* the whole image's filtered RGB */
} TileJob;

static void fill_input_rows(void *arg, size_t from, size_t to)
{
    const TileJob *job = arg;
    const PtrDenoiseInput *in = job->input;
    for (size_t ty = from; ty < to; ty++) {
        float *row = job->map + ((ty + 1) * (job->map_width + 2) + 1) * PTR_CONV_BLOCK;
        for (size_t tx = 0; tx < job->x.size; tx++) {
            size_t i = (job->y.begin + ty) * in->width + job->x.begin + tx;
            float *dst = row + tx * PTR_CONV_BLOCK;
            if (job->mode == MODE_ALBEDO)
                ptr_transfer_albedo_input(in->albedo + i * in->albedo_stride, dst);
            else if (job->mode == MODE_NORMAL)
                ptr_transfer_normal_input(in->normal + i * in->normal_stride, dst);
            else
                ptr_transfer_input(&job->transfer, in->color + i * in->color_stride,
                                   in->albedo + i * in->albedo_stride,
                                   in->normal + i * in->normal_stride, dst);
        }
    }
}

static void keep_output_rows(void *arg, size_t from, size_t to)
{
    const TileJob *job = arg;
    size_t width = job->input->width;
    for (size_t y = from; y < to; y++) {
        size_t ty = y - job->y.begin;
        for (size_t x = job->x.out_begin; x < job->x.out_end; x++) {
            const float *src =
                job->map + ((ty + 1) * (job->map_width + 2) + x - job->x.begin + 1) *
                               PTR_CONV_BLOCK;
            float *dst = job->result + (y * width + x) * 3;
            if (job->mode == MODE_ALBEDO)
                ptr_transfer_albedo_output(src, dst);
            else if (job->mode == MODE_NORMAL)
                ptr_transfer_normal_output(src, dst);
            else
                ptr_transfer_output(&job->transfer, src, dst);
        }
    }
}

/* Runs the network on one tile into job->result, its maps from maps. */
static PtrResult filter_tile(const PtrUnet *unet, PtrUnetMaps *maps, TileJob *job, int threads,
                             PtrError *err)
{
    size_t w = ptr_unet_align(job->x.size), h = ptr_unet_align(job->y.size);
    float *input = ptr_unet_map_take(maps, w, h, PTR_CONV_BLOCK);
    float *output = ptr_unet_map_take(maps, w, h, PTR_CONV_BLOCK);
    PtrResult res = PTR_ERR_NOMEM;
    if (input && output) {
        /* The pixels past the image, up to a multiple of 16, and the
         * channels past the 3 or 9 the transfer writes, are zeros: the
         * convolution reads them with weights of zero, and NaN times zero
         * is NaN. */
        memset(input, 0, (w + 2) * (h + 2) * PTR_CONV_BLOCK * sizeof *input);
        job->map_width = w;
        job->map = input;
        ptr_parallel_ranges(threads, 0, job->y.size, fill_input_rows, job);
        res = ptr_unet_run(unet, maps, input, w, h, threads, output, err);
        job->map = output;
        if (res == PTR_OK)
            ptr_parallel_ranges(threads, job->y.out_begin, job->y.out_end, keep_output_rows, job);
    } else {
        ptr_error_set(err, res, "out of memory for the denoiser's tile of %zux%zu pixels", w, h);
    }
    ptr_unet_map_give(maps, input);
    ptr_unet_map_give(maps, output);
    return res;
}

/* Runs the network over the image, tile by tile, into result (RGB, the
 * image's size), its maps from maps. The tiles overlap by as much as the
 * network needs to keep every bit of the result, and no more, which would
 * be work for nothing. */
static PtrResult filter_image(const PtrUnet *unet, PtrUnetMaps *maps, Mode mode,
                              const PtrDenoiseInput *input, size_t tile, int threads,
                              float *result, PtrError *err)
{
    const size_t overlap = ptr_unet_overlap(unet);
    if (tile <= 2 * overlap)
        return ptr_error_set(err, PTR_ERR_INTERNAL,
                             "denoiser tiles of %zu pixels: not above twice the overlap of %zu",
                             tile, overlap);
    size_t width = input->width, height = input->height;
    TileJob job = { .input = input, .mode = mode, .result = result };
    if (mode == MODE_COLOR)
        ptr_transfer_init(&job.transfer,
                          ptr_autoexposure(input->color, input->color_stride, width, height));
    size_t columns = tile_count(width, tile, overlap), rows = tile_count(height, tile, overlap);
    PtrResult res = PTR_OK;
    for (size_t j = 0; res == PTR_OK && j < rows; j++)
        for (size_t i = 0; res == PTR_OK && i < columns; i++) {
            job.y = tile_span(height, tile, overlap, rows, j);
            job.x = tile_span(width, tile, overlap, columns, i);
            res = filter_tile(unet, maps, &job, threads, err);
        }
    return res;
}

PtrResult ptr_denoise_tiled(const PtrDenoiser *denoiser, const PtrDenoiseInput *input,
                            size_t tile, int threads, float *out, size_t out_stride,
                            PtrError *err)
{
    if (tile % PTR_UNET_ALIGNMENT)
        return ptr_error_set(err, PTR_ERR_INTERNAL,
                             "denoiser tiles of %zu pixels: not a multiple of 16", tile);
    size_t pixels = input->width * input->height;
    if (!pixels)
        return PTR_OK;
    /* The tiles read the input where others have written their output: the
     * result is gathered apart and copied out at the end, so that out may be
     * the colour's own buffer. The guides, when filtered first, are kept
     * beside it. */
    int guides = denoiser->albedo != NULL;
    if (pixels > SIZE_MAX / (9 * sizeof(float)))
        return ptr_error_set(err, PTR_ERR_NOMEM, "an image of %zux%zu pixels is too large",
                             input->width, input->height);
    float *result = malloc(pixels * (guides ? 9 : 3) * sizeof(float));
    /* The feature maps of every tile and network: each tile's are the
     * memory of the tile before (PtrUnetMaps, unet.h, says why). */
    PtrUnetMaps *maps = ptr_unet_maps_new();
    if (!result || !maps) {
        free(result);
        ptr_unet_maps_free(maps);
        return ptr_error_set(err, PTR_ERR_NOMEM, "out of memory for the denoised image");
    }
    PtrDenoiseInput clean = *input;
    PtrResult res = PTR_OK;
    if (guides) {
        clean.albedo = result + pixels * 3;
        clean.normal = result + pixels * 6;
        clean.albedo_stride = clean.normal_stride = 3;
        res = filter_image(denoiser->albedo, maps, MODE_ALBEDO, input, tile, threads,
                           (float *)clean.albedo, err);
        if (res == PTR_OK)
            res = filter_image(denoiser->normal, maps, MODE_NORMAL, input, tile, threads,
                               (float *)clean.normal, err);
    }
    if (res == PTR_OK)
        res = filter_image(denoiser->color, maps, MODE_COLOR, &clean, tile, threads, result,
                           err);
    if (res == PTR_OK)
        for (size_t p = 0; p < pixels; p++)
            memcpy(out + p * out_stride, result + p * 3, 3 * sizeof(float));
    ptr_unet_maps_free(maps);
    free(result);
    return res;
}

PtrResult ptr_denoise(const PtrDenoiser *denoiser, const PtrDenoiseInput *input, int threads,
                      float *out, size_t out_stride, PtrError *err)
{
    return ptr_denoise_tiled(denoiser, input, PTR_DENOISE_TILE, threads, out, out_stride, err);
}
