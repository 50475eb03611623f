/* The path tracer: renders a scene into a scene-linear RGB float image. */
#ifndef PTR_RENDER_H
#define PTR_RENDER_H

#include <stdint.h>

#include "isect.h"
#include "rng.h"
#include "result.h"
#include "scene.h"

typedef struct PtrRenderSettings {
    int width, height;
    uint32_t samples;  /* per pixel */
    uint64_t seed;
    int max_depth;     /* rays per path at most; a path cut there adds nothing */
    int threads;       /* 0: one per online CPU */
} PtrRenderSettings;

typedef struct PtrRenderStats {
    double seconds;
    uint64_t rays; /* closest-hit queries, camera and scattered */
    int threads;
} PtrRenderStats;

/* Renders into rgb (width * height * 3 floats, rows top to bottom): each pixel
 * is the mean radiance of its samples. The image depends on the settings and
 * the scene only, never on the thread count. */
PtrResult ptr_render(const PtrScene *scene, const PtrIsectTable *isect,
                     const PtrRenderSettings *settings, float *rgb,
                     PtrRenderStats *stats, PtrError *err);

/* The radiance one camera ray carries back: exposed for tests. */
PtrVec3 ptr_trace_path(const PtrScene *scene, const PtrIsectTable *isect, PtrRay ray,
                       int max_depth, PtrRng *rng, uint64_t *rays);

#endif /* PTR_RENDER_H */
