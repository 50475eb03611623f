/* The steps of one render that the command line (app/job.c) and the library
 * (ptr.h) share, so that both give the same image for the same scene and
 * settings: the import's texture decoder, the image's size, the kernel
 * table, integrator and tree chosen for a scene, and the render into the
 * buffers the outputs take. */
#ifndef PTR_PIPELINE_H
#define PTR_PIPELINE_H

#include <stdint.h>

#include "accel/accel.h"
#include "image/image.h"
#include "importer.h"
#include "render/progressive.h"

/* Defaults of a render, as macros: the command line's --help spells them
 * out. */
#define PTR_DEFAULT_WIDTH 800
#define PTR_DEFAULT_SAMPLES 100
#define PTR_DEFAULT_MAX_DEPTH 50
#define PTR_DEFAULT_MIN_SAMPLES 32
#define PTR_DEFAULT_SEED 1
#define PTR_DEFAULT_DENOISE "balanced"

enum { PTR_MAX_IMAGE_SIZE = 1 << 16 };

/* The whole-number settings of a render whose ranges the command line's
 * options and the library's PtrRenderOptions share. */
typedef enum PtrRenderNumber {
    PTR_NUMBER_SIZE,        /* a width or a height */
    PTR_NUMBER_SAMPLES,     /* samples per pixel, and the end of a sample range */
    PTR_NUMBER_MIN_SAMPLES,
    PTR_NUMBER_MAX_DEPTH,
    PTR_NUMBER_THREADS,     /* 0: one per CPU it may run on */
} PtrRenderNumber;

/* Whether value is in number's range. */
int ptr_render_number_ok(PtrRenderNumber number, uint64_t value);
/* number's range in words, "a whole number from LO to HI", for messages. */
const char *ptr_render_number_range(PtrRenderNumber number);
/* Whether a noise threshold (--noise-threshold) is one: above 0, at most
 * 10^6. */
int ptr_noise_threshold_ok(double threshold);
/* Whether a region (--region) is one, whatever the image: 0 <= x0 < x1
 * and 0 <= y0 < y1; PTR_REGION_WORDS says so in messages. */
int ptr_region_ok(PtrRegion region);
#define PTR_REGION_WORDS "X0,Y0,X1,Y1 with 0 <= X0 < X1 and 0 <= Y0 < Y1"
/* Whether a time budget (--time) is one: above 0 seconds, at most 10^7. */
int ptr_time_budget_ok(double seconds);
/* What is wrong with a render's samples taken together: adaptive sampling
 * (noise_threshold above 0) from a first sample other than 0, or a range
 * ending past 2^30; NULL if nothing. */
const char *ptr_sample_range_problem(float noise_threshold, uint64_t first_sample,
                                     uint64_t samples);

/* The decoder of an import's textures (PtrImportOptions.textures): through
 * images, the image module's loader, which must outlive the import. */
PtrTextureDecoder ptr_texture_decoder(PtrImageLoader *images);

/* The image's width and height: those asked for, else the scene's own size
 * (scene->width, height), filling a missing one from the aspect ratio of
 * camera (the render's, which may be other than the scene's), else from the
 * scene's size, else 16:9; then divided by divisor (1: none), within
 * 1 .. PTR_MAX_IMAGE_SIZE. */
void ptr_choose_size(const PtrScene *scene, const PtrCamera *camera, int width, int height,
                     int divisor, int *out_width, int *out_height);

/* What a scene is rendered with once chosen. */
typedef struct PtrPrepared {
    PtrIsectTable isect;
    PtrIntegrator integrator;
    uint64_t scene_hash; /* ptr_scene_hash, taken before the tree's build */
    PtrAccel accel;
} PtrPrepared;

/* Fills the kernel table from the dispatch ladder at level, resolves the
 * integrator there, takes the scene's hash and builds the tree (or chooses
 * brute force) over its spheres, reordering them in place. name names the
 * scene in messages. PTR_ERR_USAGE for a kernel the build or the level
 * lacks; the tree's errors otherwise. Free with ptr_prepared_free. */
PtrResult ptr_prepare_render(PtrScene *scene, PtrKernel kernel, PtrCpuLevel level,
                             PtrIntegrator integrator, PtrAccelChoice accel, int threads,
                             const char *name, PtrPrepared *out, PtrError *err);
void ptr_prepared_free(PtrPrepared *prepared);

/* What a render fills, per pixel of the settings' region: the colour (3
 * floats), and, each NULL unless asked for, the covered share (transparent
 * settings), the samples taken (adaptive sampling) and the albedo and normal
 * passes (3 floats each). */
typedef struct PtrFrameBuffers {
    float *rgb, *alpha, *sample_counts, *albedo, *normal;
} PtrFrameBuffers;

/* Allocates the buffers the settings ask for and renders into them in
 * passes (ptr_render_progressive). name names the scene in messages. On
 * failure nothing is left to free. */
PtrResult ptr_render_frame(const PtrScene *scene, const PtrAccel *accel,
                           const PtrRenderSettings *settings, const PtrProgressiveOptions *passes,
                           const char *name, PtrFrameBuffers *out, PtrProgressiveResult *done,
                           PtrError *err);
void ptr_frame_buffers_free(PtrFrameBuffers *buffers);

#endif /* PTR_PIPELINE_H */
