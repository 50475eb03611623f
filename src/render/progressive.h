/* A render in passes of samples: progress between passes, a time budget, and
 * a clean stop when asked. */
#ifndef PTR_PROGRESSIVE_H
#define PTR_PROGRESSIVE_H

#include <signal.h>
#include <stddef.h>
#include <stdint.h>

#include "render/render.h"

typedef struct PtrProgress {
    uint32_t samples_done, samples_total;
    double fraction; /* of all samples, counting the pass under way */
    double elapsed;  /* seconds */
    uint64_t rays;   /* in the passes finished */
    double rays_seconds; /* the time those passes took */
} PtrProgress;

typedef struct PtrProgressiveOptions {
    uint32_t first_sample, samples; /* the sample indices to render */
    double time_budget;             /* seconds; stop after the pass that reaches it; 0: none */
    /* Set from a signal handler: stop after the current pass. */
    const volatile sig_atomic_t *stop;
    /* Called about ten times a second (may be NULL). */
    void (*report)(void *user, const PtrProgress *progress);
    void *user;
    /* Called after each pass (may be NULL), on the calling thread while the
     * render's threads wait, with the film so far (film.h: pixels pixels of
     * the region, stride doubles each): to be read, never written. */
    void (*pass_done)(void *user, const double *film, size_t pixels, size_t stride,
                      const PtrProgress *progress);
    void *pass_user;
} PtrProgressiveOptions;

typedef struct PtrProgressiveResult {
    uint32_t samples_done; /* from first_sample on */
    int stopped;           /* 1 if stopped by the flag, 0 if done or out of time */
    PtrRenderStats stats;  /* all passes */
} PtrProgressiveResult;

/* Renders the settings' region in passes: the first of one sample, then
 * passes sized to take about a second each. Writes the means of the samples
 * done into rgb (3 floats a pixel of the region), the same bits as one pass
 * of that many samples would give; if alpha is not NULL, the share of each
 * pixel's samples that were covered; and if sample_counts is not NULL, how
 * many samples each pixel took (fewer where adaptive sampling stopped it);
 * and with the settings' passes, the mean albedo and normal of each pixel
 * into albedo and normal (3 floats a pixel each; NULL without passes). */
PtrResult ptr_render_progressive(const PtrScene *scene, const PtrAccel *accel,
                                 const PtrRenderSettings *settings,
                                 const PtrProgressiveOptions *options, float *rgb, float *alpha,
                                 float *sample_counts, float *albedo, float *normal,
                                 PtrProgressiveResult *result,
                                 PtrError *err);

#endif /* PTR_PROGRESSIVE_H */
