/* The path tracer: renders a scene into a scene-linear RGB float image. */
#ifndef PTR_RENDER_H
#define PTR_RENDER_H

#include <stdint.h>

#include "accel/accel.h"
#include "core/result.h"
#include "core/scene.h"
#include "sampling/sampler.h"

/* A switch whose zero value, the default, is on. */
typedef enum PtrSwitch { PTR_ON, PTR_OFF } PtrSwitch;

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
    int threads;       /* 0: one per online CPU */
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
} PtrRenderSettings;

typedef struct PtrRenderStats {
    double seconds;
    uint64_t rays; /* closest-hit queries: camera, scattered and shadow rays */
    int threads;
} PtrRenderStats;

/* Called on the rendering call's own thread about ten times a second while
 * the workers run, with the share of the call's pixels done. */
typedef void (*PtrTickFn)(void *user, double fraction_done);

/* The region the settings name (the whole image if theirs is all zero), or
 * all zero if it does not lie inside the image. */
PtrRegion ptr_render_region(const PtrRenderSettings *settings);

/* Whether renders with this kernel table trace bundles of paths
 * (core/bundle.c: the assembly kernels on an AVX2 CPU) rather than one path
 * at a time (the C reference kernels, below AVX2, and always with a fixed
 * t_min). The image is the same either way. */
int ptr_render_bundles(const PtrIsectTable *isect);

/* What ptr_render_samples keeps of each pixel, in doubles: the sum of its
 * samples' radiance, the sum over its odd-numbered samples (adaptive
 * sampling's second half-buffer), how many samples it took, and whether
 * adaptive sampling stopped it (1) or not (0). */
enum {
    PTR_ACCUM_SUM = 0, PTR_ACCUM_ODD = 3, PTR_ACCUM_COUNT = 6, PTR_ACCUM_STOPPED = 7,
    PTR_ACCUM_STRIDE = 8,
};

/* The renderer reads the spheres through accel (accel->spheres, which must
 * be scene->spheres) and finds every hit, shadow rays too, with ptr_trace.
 *
 * Adds samples first .. first + count - 1 of every pixel of the region to
 * acc (PTR_ACCUM_STRIDE doubles a pixel, region rows top to bottom, zero
 * before the first call), sample by sample in index order: split into passes
 * of any size, the sums come out bit for bit the same, and never depend on
 * the thread count. tick may be NULL; stats (may be NULL) gets this call's
 * figures. */
PtrResult ptr_render_samples(const PtrScene *scene, const PtrAccel *accel,
                             const PtrRenderSettings *settings, uint32_t first, uint32_t count,
                             double *acc, PtrTickFn tick, void *user, PtrRenderStats *stats,
                             PtrError *err);

/* A zeroed accumulation buffer of pixels pixels, or NULL if memory runs out;
 * ptr_accum_free takes the same count. */
double *ptr_accum_alloc(size_t pixels);
void ptr_accum_free(double *acc, size_t pixels);

/* The mean radiance of each of pixels accumulated pixels into rgb (3 floats
 * a pixel), and if sample_counts is not NULL, how many samples each took. */
void ptr_accum_resolve(const double *acc, size_t pixels, float *rgb, float *sample_counts);

/* The whole region with settings->samples samples, as means in rgb (3 floats
 * a pixel, region rows top to bottom). */
PtrResult ptr_render(const PtrScene *scene, const PtrAccel *accel,
                     const PtrRenderSettings *settings, float *rgb,
                     PtrRenderStats *stats, PtrError *err);

/* The outward unit normal where ray met the sphere hit names. */
static inline PtrVec3 ptr_hit_normal(const PtrSpheres *spheres, const PtrRay *ray, const PtrHit *hit)
{
    PtrVec3 p = v3_madd(v3(ray->org[0], ray->org[1], ray->org[2]),
                        v3(ray->dir[0], ray->dir[1], ray->dir[2]), hit->t);
    return v3_normalize(v3_sub(p, ptr_sphere_centre(spheres, hit->sphere)));
}

/* A ray leaving the surface of a sphere along dir from the point where
 * outward_normal meets it: its origin is that point pushed off the surface,
 * along the normal and to the side dir goes, by a bound on the float error of
 * locating it, so that it cannot hit the same surface again at t ~ 0.
 *
 * How far: relative to the
 * magnitude of the numbers that locate it (|centre| + radius): the point is
 * re-projected onto the sphere, which leaves a few ulps of that magnitude of
 * error, and the kernel's f.f - r^2 adds a few more. Measured by
 * tests/stability/test_precision.c over 2 million hit points per level
 * (radii 1e-4 to 1e6, centres up to 1e7 away, down to grazing): 2^-23 lets
 * outward rays hit their own sphere again, 2^-22 stops grazing inward rays
 * short of the far side, 2^-21 and above never fail. Smaller is better (the
 * offset shifts contact shadows), so the smallest safe power of two. */
#define PTR_SPAWN_OFFSET_SCALE 0x1.0p-21f

static inline PtrRay ptr_spawn_ray(PtrVec3 centre, float radius, PtrVec3 outward_normal,
                                   PtrVec3 dir)
{
    float offset = PTR_SPAWN_OFFSET_SCALE * (v3_max_abs(centre) + radius);
    offset = v3_dot(dir, outward_normal) < 0.0f ? -offset : offset;
    PtrVec3 o = v3_add(centre, v3_scale(outward_normal, radius + offset));
    return (PtrRay){ { o.x, o.y, o.z }, 0.0f, { dir.x, dir.y, dir.z }, INFINITY };
}

#endif /* PTR_RENDER_H */
