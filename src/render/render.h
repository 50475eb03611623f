/* The path tracer: renders a scene into a scene-linear RGB float image. */
#ifndef PTR_RENDER_H
#define PTR_RENDER_H

#include <stdint.h>

#include "accel/accel.h"
#include "base/cpu.h"
#include "base/result.h"
#include "render/film.h"
#include "render/settings.h"
#include "scene/scene.h"

typedef struct PtrRenderStats {
    double seconds;
    uint64_t rays; /* closest-hit queries: camera, scattered and shadow rays */
    int threads;
    /* Thread-seconds the threads sat idle: each from its last tile to the
     * call's end and, over passes (progressive.h), all between two passes.
     * Over threads x seconds, the share of the cores a render left unused. */
    double idle_seconds;
} PtrRenderStats;

/* Called on the rendering call's own thread about ten times a second while
 * the workers run, with the share of the call's pixels done. */
typedef void (*PtrTickFn)(void *user, double fraction_done);

/* The region the settings name (the whole image if theirs is all zero), or
 * all zero if it does not lie inside the image. */
PtrRegion ptr_render_region(const PtrRenderSettings *settings);

/* The dispatch ladder's integrator for a CPU level: bundles from AVX2 on,
 * where the build has them (they lose below: docs/bundles.md), else paths. */
PtrIntegrator ptr_integrator_for_level(PtrCpuLevel level);

/* Whether the integrator can run at the CPU level. */
int ptr_integrator_available(PtrIntegrator integrator, PtrCpuLevel level);

/* The integrator asked for, or for PTR_INTEGRATOR_AUTO the ladder's at the
 * CPU level. */
PtrIntegrator ptr_integrator_resolve(PtrIntegrator integrator, PtrCpuLevel level);

/* The integrator a render with these settings uses: theirs resolved at
 * ptr_cpu_level (a caller that caps the level lower resolves it itself), but
 * always paths with a fixed t_min, which the bundles do not take. */
PtrIntegrator ptr_render_integrator(const PtrRenderSettings *settings);

/* "paths" or "bundles", and back ("auto" too); parse returns PTR_ERR_USAGE
 * for anything else. */
const char *ptr_integrator_name(PtrIntegrator integrator);
PtrResult ptr_integrator_parse(const char *text, PtrIntegrator *integrator, PtrError *err);

/* The renderer reads the spheres through accel (accel->spheres, which must
 * be scene->spheres) and finds every hit, shadow rays too, with ptr_trace.
 *
 * Adds samples first .. first + count - 1 of every pixel of the region to
 * acc (ptr_accum_stride doubles a pixel, region rows top to bottom, zero
 * before the first call), sample by sample in index order: split into passes
 * of any size, the sums come out bit for bit the same, and never depend on
 * the thread count. tick may be NULL; stats (may be NULL) gets this call's
 * figures. */
PtrResult ptr_render_samples(const PtrScene *scene, const PtrAccel *accel,
                             const PtrRenderSettings *settings, uint32_t first, uint32_t count,
                             double *acc, PtrTickFn tick, void *user, PtrRenderStats *stats,
                             PtrError *err);

/* The whole region with settings->samples samples, as means in rgb (3 floats
 * a pixel, region rows top to bottom). */
PtrResult ptr_render(const PtrScene *scene, const PtrAccel *accel,
                     const PtrRenderSettings *settings, float *rgb,
                     PtrRenderStats *stats, PtrError *err);

#endif /* PTR_RENDER_H */
