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
    /* 0: rays leave a surface by ptr's scaled offset (ptr_spawn_ray). When
     * positive, they leave it the seed renderer's way instead, from the hit
     * point with this fixed t_min (0.001 there): the counter-example the
     * stability suite measures against. */
    float fixed_tmin;
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
                       const PtrRenderSettings *settings, PtrRng *rng, uint64_t *rays);

/* The outward unit normal where ray met the sphere hit names. */
PtrVec3 ptr_hit_normal(const PtrSpheres *spheres, const PtrRay *ray, const PtrHit *hit);

/* A ray leaving the surface of a sphere along dir from the point where
 * outward_normal meets it: its origin is that point pushed off the surface,
 * along the normal and to the side dir goes, by a bound on the float error of
 * locating it, so that it cannot hit the same surface again at t ~ 0. */
PtrRay ptr_spawn_ray(PtrVec3 centre, float radius, PtrVec3 outward_normal, PtrVec3 dir);

#endif /* PTR_RENDER_H */
