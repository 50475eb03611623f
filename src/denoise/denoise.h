/* Denoising a rendered image with Open Image Denoise's trained U-Net, run by
 * ptr itself: its weights read from a tensor archive (tza.h), its
 * convolutions through the kernel table (conv.h), its pre- and
 * post-processing for HDR colour with albedo and normal guides as OIDN's
 * own does them. The output depends only on the inputs and the weights:
 * never on the thread count or the CPU level. */
#ifndef PTR_DENOISE_H
#define PTR_DENOISE_H

#include <stddef.h>

#include "base/cpu.h"
#include "base/result.h"

typedef enum PtrDenoiseQuality {
    PTR_DENOISE_FAST,     /* the small network */
    PTR_DENOISE_BALANCED, /* the default network */
    PTR_DENOISE_HIGH,     /* the large networks: albedo and normal filtered
                           * first, then the colour with them as clean guides */
} PtrDenoiseQuality;

/* Parses "fast", "balanced" or "high" (the option-value convention). */
PtrResult ptr_denoise_quality_parse(const char *text, PtrDenoiseQuality *out, PtrError *err);
/* The quality's name, as parsed: a string that lives as long as the process. */
const char *ptr_denoise_quality_name(PtrDenoiseQuality quality);

typedef struct PtrDenoiser PtrDenoiser;

/* Loads the weights of this quality from weights_dir (NULL: $PTR_WEIGHTS_DIR,
 * else the installed share/ptr/weights) and fills the kernel table for this
 * CPU level. A missing or broken weight file is PTR_ERR_INSTALL, one line
 * naming the path and the fix. */
PtrResult ptr_denoiser_new(PtrDenoiseQuality quality, const char *weights_dir,
                           PtrCpuLevel level, PtrDenoiser **out, PtrError *err);

void ptr_denoiser_free(PtrDenoiser *denoiser);

/* The image to denoise: width x height pixels, row by row; each buffer's
 * pixel i starts at buffer + i * stride (floats), so RGBA buffers serve
 * (their fourth float is neither read nor written). color is linear HDR
 * RGB; albedo is in [0, 1]; normal is a unit vector in any space, (0,0,0)
 * where nothing was hit. */
typedef struct PtrDenoiseInput {
    const float *color, *albedo, *normal;
    size_t color_stride, albedo_stride, normal_stride;
    size_t width, height;
} PtrDenoiseInput;

/* Writes the denoised colour, RGB, pixel i at out + i * out_stride (which
 * may be input->color's buffer), on threads threads. PTR_ERR_NOMEM. */
PtrResult ptr_denoise(const PtrDenoiser *denoiser, const PtrDenoiseInput *input,
                      int threads, float *out, size_t out_stride, PtrError *err);

/* The network runs on tiles of at most PTR_DENOISE_TILE pixels a side,
 * which overlap by what the network needs (ptr_unet_overlap: 80 pixels for
 * UNet, 96 for UNetLarge) and start at multiples of 16:
 * each output pixel is computed from the same values in the same order as
 * in one tile of the whole image, so the tiles bound memory (the maps of a
 * tile: at most about 450 MB alive at once for the default network, 550 MB
 * for the large, 500 and 870 MB kept for reuse) without changing a bit of
 * the result. The tiling depends only on the image's size and the
 * network. */
enum { PTR_DENOISE_TILE = 768 };

/* ptr_denoise with tiles of at most tile pixels a side (a multiple of 16
 * above twice the overlap), for the tests of the tiling. */
PtrResult ptr_denoise_tiled(const PtrDenoiser *denoiser, const PtrDenoiseInput *input,
                            size_t tile, int threads, float *out, size_t out_stride,
                            PtrError *err);

#endif /* PTR_DENOISE_H */
