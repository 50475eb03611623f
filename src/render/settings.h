/* What a render is asked for: the image, its samples and how paths are
 * traced. The steps of a path (path.h) read it, as does the render that
 * runs them (render.h). */
#ifndef PTR_SETTINGS_H
#define PTR_SETTINGS_H

#include <stdint.h>

#include "sampling/sampler.h"

/* A switch whose zero value, the default, is on. */
typedef enum PtrSwitch { PTR_ON, PTR_OFF } PtrSwitch;

/* How paths are traced, the image the same bit for bit either way: one at a
 * time (render.c, the reference), or in bundles of eight, one path a lane
 * (bundle.c, built for AVX2 on x86-64). */
typedef enum PtrIntegrator {
    PTR_INTEGRATOR_AUTO,    /* the dispatch ladder's, at a CPU level */
    PTR_INTEGRATOR_PATHS,
    PTR_INTEGRATOR_BUNDLES,
} PtrIntegrator;

/* Pixels x0 <= x < x1, y0 <= y < y1 of the full image. */
typedef struct PtrRegion {
    int x0, y0, x1, y1;
} PtrRegion;

typedef struct PtrRenderSettings {
    int width, height; /* the full image */
    PtrRegion region;  /* the pixels to render; all zero: the whole image */
    uint32_t samples;  /* per pixel, for ptr_render */
    uint64_t seed;
    int max_depth;     /* rays per path at most, from the camera or a scattering
                        * (shadow rays do not count); a path cut there adds
                        * nothing */
    int threads;       /* 0: one per CPU it may run on */
    /* 0: rays leave a surface by ptr's scaled offset (ptr_spawn_ray). When
     * positive, they leave it the seed renderer's way instead, from the hit
     * point with this fixed t_min (0.001 there): the counter-example the
     * stability suite measures against. */
    float fixed_tmin;
    PtrSamplerKind sampler;
    PtrSwitch direct_lighting; /* light sampling of emissive spheres, with MIS */
    /* Adaptive sampling: above 0, a pixel stops once its error estimate
     * falls below this, checked after min_samples and every 16 samples;
     * sample indices must then start at 0. */
    float noise_threshold;
    uint32_t min_samples;
    PtrIntegrator integrator;
    /* A transparent background: a sample whose camera ray meets no sphere
     * adds no radiance (the sky it sees is left out), and adaptive sampling
     * weighs the noise of coverage too. Coverage is counted either way. */
    int transparent;
    /* Albedo and normal passes (path.h, PtrPathPass): the film then keeps
     * their sums too (film.h, ptr_accum_stride). */
    int passes;
} PtrRenderSettings;

#endif /* PTR_SETTINGS_H */
