/* What every way of tracing a path shares: the job a render's paths belong
 * to, and the steps of a path that the path tracer takes one path at a time
 * (render.c) and its bundles take eight at a time (bundle.c). Both call these
 * same functions, so a path is the same path either way, bit for bit. */
#ifndef PTR_PATH_H
#define PTR_PATH_H

#include <stdint.h>

#include "accel/accel.h"
#include "accel/huge.h"
#include "base/trig.h"
#include "render/camera.h"
#include "render/film.h"
#include "render/lights.h"
#include "render/material.h"
#include "render/settings.h"
#include "sampling/sampler.h"

typedef struct PtrPathJob {
    const PtrScene *scene;
    const PtrAccel *accel;
    const PtrRenderSettings *settings;
    PtrView view;
    PtrLights lights;
    int sample_lights; /* light sampling is on and there is an emitter */
    PtrRegion region;
    uint32_t first, count; /* the sample indices of this call */
    double *sums;          /* ptr_accum_stride doubles a pixel of the region */
} PtrPathJob;

/* Threads take the image in tiles of this many pixels square. */
enum { PTR_TILE_SIZE = 16, PTR_TILE_PIXELS = PTR_TILE_SIZE * PTR_TILE_SIZE };

/* Adaptive sampling looks at a pixel only after sample counts that are
 * multiples of this (from the minimum on): the decision depends on the
 * pixel's own samples alone, never on passes or threads, and Sobol' points
 * are complete nets at these counts. */
enum { PTR_ADAPTIVE_STEP = 16 };

/* A vertex where an emitter was sampled: what the next vertex needs to
 * weigh the emission the scattered ray finds against that sample. */
typedef struct PtrLitVertex {
    int sampled;       /* 0: the emission found next counts fully */
    PtrVec3 point;
    uint32_t sphere;   /* the sphere it lies on */
    int side;          /* 1 on its outside, -1 on its inside */
    float scatter_pdf; /* of the direction taken (ptr_material_pdf) */
} PtrLitVertex;

/* Whether a path may trace its ray number depth, counting from 0 (the
 * camera's): max_depth rays at most. */
static inline int ptr_path_may_trace(const PtrRenderSettings *settings, int depth)
{
    return depth < settings->max_depth;
}

/* Whether a path whose ray number depth hit a surface goes on from there:
 * the surface scattered it (did not absorb it), the throughput after the
 * scattering is not zero, and the path may trace another ray. Written with
 * & and !(<= 0), as the bundles' vector loops need it. */
static inline int ptr_path_goes_on(const PtrRenderSettings *settings, int depth, int scattered,
                                   PtrVec3 throughput)
{
    return scattered & !(v3_max_comp(throughput) <= 0.0f) & ptr_path_may_trace(settings, depth + 1);
}

/* The albedo of material at sphere: tinted by the sphere's own colour where
 * the scene gives spheres colours. */
static inline PtrVec3 ptr_path_albedo(const PtrSpheres *spheres, uint32_t sphere, PtrVec3 albedo)
{
    return spheres->color ? v3_mul(albedo, ptr_sphere_color(spheres, sphere)) : albedo;
}

/* The vertex a path makes at point on sphere with a material of this kind,
 * at this depth, arriving from outside the sphere (entering) or inside: an
 * emitter is sampled there if light sampling is on, the material has a
 * density to weigh the sample against (ptr_material_has_density) and the
 * path may take another ray. */
static inline PtrLitVertex ptr_path_vertex(const PtrPathJob *job, PtrMaterialKind kind, int depth,
                                           PtrVec3 point, uint32_t sphere, int entering)
{
    return (PtrLitVertex){ .sampled = job->sample_lights && ptr_material_has_density(kind) &&
                                      ptr_path_may_trace(job->settings, depth + 1),
                           .point = point, .sphere = sphere, .side = entering ? 1 : -1 };
}

/* What a ray adds to its path's radiance where it ends: where it met
 * nothing (hit 0), the sky's radiance along it; where it met a surface, the
 * surface's emission weighed by weight (ptr_path_weighs_emission), or
 * nothing if the surface emits none (adding a zero would turn a -0 into
 * +0). Both sides are computed and one kept, so a vector loop can take it. */
static inline PtrVec3 ptr_path_add_found(PtrVec3 radiance, PtrVec3 throughput, int hit,
                                         PtrVec3 sky, PtrVec3 emission, float weight)
{
    PtrVec3 found = hit ? v3_scale(v3_mul(throughput, emission), weight) : v3_mul(throughput, sky);
    int adds = !hit | (v3_max_comp(emission) > 0.0f);
    return adds ? v3_add(radiance, found) : radiance;
}

/* Whether a path meets and leaves sphere in double precision
 * (ptr_huge_surface, ptr_huge_spawn_ray) rather than float: where the
 * sphere is huge, unless rays leave surfaces with a fixed t_min. */
static inline int ptr_path_in_double(const PtrPathJob *job, uint32_t sphere)
{
    return ptr_is_huge(job->scene, sphere) && job->settings->fixed_tmin == 0.0f;
}

static inline double *ptr_path_pixel_sums(const PtrPathJob *job, int x, int y)
{
    const PtrRegion *r = &job->region;
    return job->sums + ptr_accum_stride(job->settings->passes) *
                           ((size_t)(y - r->y0) * (size_t)(r->x1 - r->x0) + (size_t)(x - r->x0));
}

/* The sampler key of pixel (x, y). Keyed by full-image pixel, so a region
 * renders the very samples the whole image would. */
static inline uint64_t ptr_path_pixel_key(const PtrPathJob *job, int x, int y)
{
    const PtrRenderSettings *s = job->settings;
    uint64_t pixel = (uint64_t)y * (uint64_t)s->width + (uint64_t)x;
    return ptr_sampler_for_sample(s->sampler, s->seed, pixel, 0).pixel_key;
}

/* The camera ray through pixel (x, y) of the sample whose pairs
 * PTR_DIM_PIXEL and PTR_DIM_LENS are pixel_bits and lens_bits. */
static inline void ptr_path_camera_ray_from_bits(const PtrPathJob *job,
                                                 const uint32_t pixel_bits[2],
                                                 const uint32_t lens_bits[2], int x, int y,
                                                 PtrVec3 *origin, PtrVec3 *dir)
{
    float lens_r = sqrtf(ptr_sample_float(lens_bits[0])), sin_phi, cos_phi;
    ptr_sincos_turns(ptr_sample_float(lens_bits[1]), &sin_phi, &cos_phi);
    ptr_view_ray(&job->view, x, y, ptr_sample_float(pixel_bits[0]),
                 ptr_sample_float(pixel_bits[1]), lens_r * cos_phi, lens_r * sin_phi, origin,
                 dir);
}

/* The camera ray of sample index of pixel (x, y). */
static inline void ptr_path_camera_ray(const PtrPathJob *job, uint64_t pixel_key, uint32_t index,
                                       int x, int y, PtrVec3 *origin, PtrVec3 *dir)
{
    PtrSamplerKind kind = job->settings->sampler;
    uint32_t pixel_bits[2], lens_bits[2];
    ptr_sampler_pair_bits(kind, pixel_key, index, PTR_DIM_PIXEL, pixel_bits);
    ptr_sampler_pair_bits(kind, pixel_key, index, PTR_DIM_LENS, lens_bits);
    ptr_path_camera_ray_from_bits(job, pixel_bits, lens_bits, x, y, origin, dir);
}

/* Where ray met the sphere hit names: the point on its surface and the
 * outward normal there, in double where ptr_path_in_double says (for the
 * stability suite's fixed t_min, the point along the ray, as the seed
 * renderer took it). */
void ptr_path_surface(const PtrPathJob *job, const PtrRay *ray, const PtrHit *hit,
                      PtrVec3 *point, PtrVec3 *normal);

/* A ray leaving the surface of sphere at point (outward normal there) along
 * dir, by the settings' method, in double where ptr_path_in_double says. */
PtrRay ptr_path_leave(const PtrPathJob *job, uint32_t sphere, PtrVec3 point,
                      PtrVec3 outward_normal, PtrVec3 dir);

/* Light sampling at vertex at of material m (n: the normal on the side
 * the path arrives from): one emitter picked by power, one direction
 * towards it, one shadow ray (counted in *rays), weighed against
 * scattering by the material's own density and BSDF (ptr_material_pdf,
 * ptr_material_eval). */
PtrVec3 ptr_path_sample_emitter(const PtrPathJob *job, const PtrSampler *sampler, int bounce,
                                const PtrMaterial *m, const PtrLitVertex *at, PtrVec3 n,
                                PtrVec3 outward_normal, uint64_t *rays);

/* Whether the emission a ray found on a surface emitting this is weighed
 * against light sampling at the vertex it left (from), by
 * ptr_path_emission_weight: where an emitter was sampled there and the
 * surface emits. Otherwise it counts fully (weight 1). */
static inline int ptr_path_weighs_emission(const PtrLitVertex *from, PtrVec3 emission)
{
    return from->sampled && v3_max_comp(emission) > 0.0f;
}

/* The weight of the emission a scattered ray found on emitter (along dir,
 * at point, outward normal there) after light sampling at vertex from. */
float ptr_path_emission_weight(const PtrPathJob *job, const PtrLitVertex *from, uint32_t emitter,
                               PtrVec3 dir, PtrVec3 point, PtrVec3 normal);

/* What a path gives the albedo and normal passes: the albedo and normal
 * of the first surface it meets that is not a perfect mirror (metal
 * without fuzz) or glass, which the passes see through, as a denoiser
 * wants its guides (docs/scenes.md, "Passes"). The albedo seen through
 * such surfaces is tinted by theirs; a path that ends on one (its last ray
 * taken) keeps that surface's own; a ray that meets nothing gives the sky
 * clamped to [0, 1] and a zero normal. Normals are in world space, on the
 * side the ray arrives from. */
typedef struct PtrPathPass {
    PtrVec3 albedo, normal;
    PtrVec3 tint;  /* the albedos of the surfaces seen through so far */
    int found;     /* the surface the passes record is found */
} PtrPathPass;

static inline PtrPathPass ptr_path_pass_start(void)
{
    return (PtrPathPass){ .tint = v3_splat(1.0f) };
}

static inline PtrVec3 ptr_path_pass_clamp(PtrVec3 c)
{
    return v3(ptr_minf(ptr_maxf(c.x, 0.0f), 1.0f), ptr_minf(ptr_maxf(c.y, 0.0f), 1.0f),
              ptr_minf(ptr_maxf(c.z, 0.0f), 1.0f));
}

/* The passes at a surface of this kind, fuzz and albedo, with normal n on
 * the side the ray arrives from. */
static inline void ptr_path_pass_surface(PtrPathPass *pass, PtrMaterialKind kind, float fuzz,
                                         PtrVec3 albedo, PtrVec3 n)
{
    if (pass->found)
        return;
    albedo = ptr_path_pass_clamp(albedo);
    pass->albedo = v3_mul(pass->tint, albedo);
    pass->normal = n;
    pass->tint = pass->albedo;
    pass->found = !ptr_material_is_see_through(kind, fuzz);
}

/* The passes where a ray met nothing and saw sky. */
static inline void ptr_path_pass_sky(PtrPathPass *pass, PtrVec3 sky)
{
    if (pass->found)
        return;
    pass->albedo = v3_mul(pass->tint, ptr_path_pass_clamp(sky));
    pass->normal = v3_splat(0.0f);
    pass->found = 1;
}

/* Adds radiance as sample index of the pixel whose sums acc are, covered
 * or not (whether its camera ray hit a sphere), with its passes where the
 * settings ask for them (pass is then not NULL), and decides whether
 * adaptive sampling stops the pixel there. */
void ptr_path_accumulate(const PtrRenderSettings *settings, double *acc, uint32_t index,
                         PtrVec3 radiance, int covered, const PtrPathPass *pass);

/* Renders the job's samples of the pixels of [x0, x1) x [y0, y1), counting
 * rays: a path at a time (render.c) or in bundles (bundle.c, built for AVX2
 * on x86-64). */
#define PTR_DECL_RENDER_TILE(name)                                            \
    void name(const PtrPathJob *job, int x0, int y0, int x1, int y1, uint64_t *rays)

typedef PTR_DECL_RENDER_TILE((*PtrRenderTileFn));

PTR_DECL_RENDER_TILE(ptr_render_tile_bundled_avx2);

#endif /* PTR_PATH_H */
