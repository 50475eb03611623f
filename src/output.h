/* From the renderer's scene-linear float image to a file on disk. */
#ifndef PTR_OUTPUT_H
#define PTR_OUTPUT_H

#include <stdint.h>

#include "result.h"

typedef struct PtrOutputInfo {
    const char *scene_path;
    const char *kernel;
    uint32_t samples;
    uint64_t seed;
    int max_depth;
    double render_seconds;
    int half; /* float formats: store half instead of float */
} PtrOutputInfo;

/* Fails early, before any rendering, if no writer exists for the output's
 * extension (PTR_ERR_USAGE) or its folder cannot take the file
 * (PTR_ERR_OUTPUT). */
PtrResult ptr_output_check(const char *path, PtrError *err);

/* Float formats (.exr, .hdr) keep scene-linear values; every other format is
 * encoded with the sRGB transfer curve and quantised to 8 bits. The file is
 * replaced atomically. */
PtrResult ptr_output_write(const char *path, int width, int height, const float *rgb,
                           const PtrOutputInfo *info, PtrError *err);

/* The sRGB transfer function (IEC 61966-2-1) for one linear value in [0, 1]. */
float ptr_srgb_encode(float linear);

#endif /* PTR_OUTPUT_H */
