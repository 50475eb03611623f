/* From the renderer's scene-linear float image to a file on disk. */
#ifndef PTR_OUTPUT_H
#define PTR_OUTPUT_H

#include <stdint.h>

#include "base/result.h"
#include "color/color.h"
#include "denoise/denoise.h"
#include "image/image.h"

/* What each channel is stored as. Integer depths always hold the
 * display-referred image (the view applied, clamped to [0, 1], rounded);
 * float depths hold scene-linear values unless bake_view is set. */
typedef enum PtrDepth {
    PTR_DEPTH_DEFAULT, /* float for .exr and .hdr, else 8 bits */
    PTR_DEPTH_8,
    PTR_DEPTH_16,
    PTR_DEPTH_HALF,
    PTR_DEPTH_FLOAT,
} PtrDepth;

/* How an image is stored and shown: the output's options (--depth,
 * --dither, --bake-view; --display, --view, --look and --exposure through
 * color). */
typedef struct PtrOutputSettings {
    PtrDepth depth;
    const PtrColor *color; /* the display, view, look and exposure in force */
    float exposure;        /* stops, as given to ptr_color_select (for metadata) */
    int bake_view;         /* float depths too get the display-referred image */
    int dither;            /* 8-bit: dither before rounding */
} PtrOutputSettings;

typedef struct PtrOutputInfo {
    const char *scene_path;
    uint64_t scene_hash;   /* ptr_scene_hash: merge refuses parts of other scenes */
    /* scene_hash is the older fingerprint of parts merged (FNV-1a), kept
     * under its own name, ptr:scene_hash, not ptr:scene_xxh3. */
    int legacy_scene_hash;
    const char *kernel;
    const char *accel;     /* "brute" or "bvh" */
    size_t spheres;
    double import_seconds, build_seconds;
    uint32_t sample_first; /* the samples taken: first .. first + samples - 1 */
    uint32_t samples;
    int interrupted;       /* the render stopped before all samples asked for */
    uint64_t seed;
    int max_depth;
    const char *sampler;   /* the estimator: ptr_sampler_name and light sampling */
    int direct_lighting;
    float noise_threshold; /* adaptive sampling; 0: off */
    uint32_t min_samples;
    const float *sample_counts; /* per pixel, written as an EXR channel (may be NULL) */
    /* The albedo and normal passes, three floats a pixel each, written as
     * EXR layers (NULL: none; only EXR takes them: ptr_output_check). */
    const float *albedo, *normal;
    /* With a denoiser (and both passes), the file gets the denoised colour,
     * and an EXR the noisy one too, as a layer. */
    const PtrDenoiser *denoiser;
    /* Without a denoiser: the colour before denoising, when the colour
     * given is denoised already, for an EXR's layer (NULL: not denoised). */
    const float *noisy;
    const char *denoise_quality; /* the denoiser's name, for the metadata */
    int threads;           /* the denoiser's; 0: one per CPU it may run on */
    /* Per pixel, the share of its samples that were covered (may be NULL):
     * the image's alpha, the RGB given then premultiplied by it. */
    const float *alpha;
    double render_seconds;
    PtrOutputSettings output;
} PtrOutputInfo;

/* Parses "8", "16", "half" or "float"; PTR_ERR_USAGE for anything else. */
PtrResult ptr_depth_parse(const char *text, PtrDepth *depth, PtrError *err);

/* Whether an exposure (--exposure) is one: -64 to 64 stops. */
int ptr_exposure_ok(double stops);

/* Fails early, before any rendering, if no writer exists for the output's
 * extension or it cannot store that depth, or an alpha channel if alpha is
 * set, or passes if passes is set (EXR only) (PTR_ERR_USAGE), or its folder
 * cannot take the file (PTR_ERR_OUTPUT). images loads the module for
 * formats other than EXR (ptr_image_read). */
PtrResult ptr_output_check(PtrImageLoader *images, const char *path, PtrDepth depth, int alpha,
                           int passes, PtrError *err);

/* The denoised colour of the image (as ptr_output_write takes it) into
 * *out (for free), from its colour (premultiplied by alpha, if there is
 * one) and info's passes, through info's denoiser; path names it in
 * messages. */
PtrResult ptr_output_denoise(const char *path, const PtrImageLayout *layout, const float *rgb,
                             const PtrOutputInfo *info, float **out, PtrError *err);

/* Writes the image (RGB scene-linear, rows top to bottom, laid out in the
 * full image as layout says) as info says, denoised first if info has a
 * denoiser. The file is replaced atomically.
 * With an alpha channel, EXR stores the colour premultiplied, as OpenEXR
 * defines it, and every other format straight (divided by alpha); the view
 * of an integer format is taken of the straight colour, as OpenColorIO's
 * transforms expect. */
PtrResult ptr_output_write(PtrImageLoader *images, const char *path, const PtrImageLayout *layout,
                           const float *rgb, const PtrOutputInfo *info, PtrError *err);

#endif /* PTR_OUTPUT_H */
