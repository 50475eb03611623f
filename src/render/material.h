/* Scattering at a surface, as the seed's renderer models it: Lambertian
 * diffuse, metal with fuzz, and dielectric with Fresnel (Schlick)
 * reflect-or-refract and total internal reflection.
 *
 * The pieces are inline and branch-free where they can be: the path tracer
 * calls them one path at a time, and its bundles (render/bundle.c) call them
 * lane by lane in loops the compiler vectorises; both compute the same bits.
 * Everything a path asks of a material is here, so a new material is a case
 * of each ptr_scatter_* and ptr_material_* function below that names kinds,
 * and of nothing else in the render. */
#ifndef PTR_MATERIAL_H
#define PTR_MATERIAL_H

#include <math.h>

#include "base/trig.h"
#include "scene/scene.h"

/* Samples an outgoing direction for a ray arriving along unit in_dir at a
 * surface whose outward unit normal is outward_normal, from three uniform
 * numbers in [0, 1): u[0] and u[1] pick a direction, u[2] the Fresnel choice
 * of glass or the fuzz radius of metal. On return *out_dir is a unit vector
 * and *attenuation the factor the path's throughput takes (the BSDF times
 * the cosine over the density of the direction). Returns 0 if the ray is
 * absorbed (a fuzzed metal ray pointing into the surface). */
int ptr_scatter(const PtrMaterial *material, PtrVec3 in_dir, PtrVec3 outward_normal,
                const float u[3], PtrVec3 *out_dir, PtrVec3 *attenuation);

/* A uniformly distributed unit vector from two uniform numbers. */
static inline PtrVec3 ptr_uniform_sphere(float u0, float u1)
{
    /* Archimedes: z is uniform on [-1, 1] for a uniform point on the sphere. */
    float z = 1.0f - 2.0f * u0;
    float r = sqrtf(ptr_maxf(0.0f, 1.0f - z * z));
    float sin_phi, cos_phi;
    ptr_sincos_turns(u1, &sin_phi, &cos_phi);
    return v3(r * cos_phi, r * sin_phi, z);
}

/* Schlick's approximation of Fresnel reflectance for the cosine of the angle
 * of incidence and the ratio of refractive indices (incident / transmitted). */
static inline float ptr_schlick(float cosine, float eta_ratio)
{
    float r0 = (1.0f - eta_ratio) / (1.0f + eta_ratio);
    r0 = r0 * r0;
    float m = 1.0f - cosine;
    return r0 + (1.0f - r0) * (m * m) * (m * m) * m;
}

/* Mirror reflection of d about the unit normal n. */
static inline PtrVec3 ptr_reflect(PtrVec3 d, PtrVec3 n)
{
    return v3_sub(d, v3_scale(n, 2.0f * v3_dot(d, n)));
}

/* Diffuse: the normal n (on the side the ray arrives from) plus a uniform
 * unit vector is cosine-distributed about it, the density ptr_diffuse_pdf
 * gives. */
static inline PtrVec3 ptr_scatter_diffuse(PtrVec3 n, float u0, float u1)
{
    PtrVec3 dir = v3_add(n, ptr_uniform_sphere(u0, u1));
    /* The sample can cancel the normal; fall back to it then. */
    return v3_max_abs(dir) < 1e-6f ? n : v3_normalize(dir);
}

/* Dielectric of index ior, n on the side the ray arrives from: reflect or
 * refract as the Fresnel coin u decides. */
static inline PtrVec3 ptr_scatter_dielectric(float ior, PtrVec3 d, PtrVec3 n, int entering,
                                             float u)
{
    float eta_ratio = entering ? 1.0f / ior : ior;
    float cos_theta = ptr_minf(-v3_dot(d, n), 1.0f);
    float sin_theta = sqrtf(ptr_maxf(0.0f, 1.0f - cos_theta * cos_theta));
    int reflects = eta_ratio * sin_theta > 1.0f || ptr_schlick(cos_theta, eta_ratio) > u;
    PtrVec3 perp = v3_scale(v3_madd(d, n, cos_theta), eta_ratio);
    float parallel = -sqrtf(fabsf(1.0f - v3_dot(perp, perp)));
    PtrVec3 refracted = v3_normalize(v3_madd(perp, n, parallel));
    return reflects ? ptr_reflect(d, n) : refracted;
}

/* Metal's fuzz: a uniform point in the ball of radius fuzz (uniform
 * direction, radius the cube root of a uniform number), added to the mirror
 * direction. */
static inline PtrVec3 ptr_fuzz_offset(float fuzz, const float u[3])
{
    return v3_scale(v3_scale(ptr_uniform_sphere(u[0], u[1]), cbrtf(u[2])), fuzz);
}

/* The normal on the side a ray along dir arrives from. */
static inline PtrVec3 ptr_facing_normal(PtrVec3 dir, PtrVec3 outward_normal)
{
    return v3_dot(dir, outward_normal) < 0.0f ? outward_normal : v3_neg(outward_normal);
}

/* The direction a ray along unit d leaves a surface of this kind and index
 * of refraction in (outward_normal: the surface's outward unit normal), u as
 * for ptr_scatter: every material's direction computed and the kind's kept,
 * without branches, so that the bundles' loops over lanes vectorise (where
 * the kind is a constant, the compiler drops the others: always inlined, as
 * gcc would not for ptr_scatter's four cases, which then computed all three
 * for every kind). Fuzzy metal takes ptr_scatter_fuzzy_metal instead.
 * *scattered is 0 where the ray is absorbed. */
static inline __attribute__((always_inline)) PtrVec3
ptr_scatter_direction(PtrMaterialKind kind, float ior, PtrVec3 d, PtrVec3 outward_normal,
                      const float u[3], int *scattered)
{
    PtrVec3 n = ptr_facing_normal(d, outward_normal);
    PtrVec3 diffuse = ptr_scatter_diffuse(n, u[0], u[1]);
    PtrVec3 mirror = ptr_reflect(d, n);
    PtrVec3 glass = ptr_scatter_dielectric(ior, d, n, v3_dot(d, outward_normal) < 0.0f, u[2]);
    *scattered = (kind != PTR_MATERIAL_METAL) | (v3_dot(mirror, n) > 0.0f);
    return kind == PTR_MATERIAL_DIFFUSE ? diffuse
           : kind == PTR_MATERIAL_METAL ? v3_normalize(mirror)
                                        : glass;
}

/* Whether a material of this kind and fuzz scatters by
 * ptr_scatter_fuzzy_metal rather than ptr_scatter_direction. */
static inline int ptr_scatter_is_fuzzy(PtrMaterialKind kind, float fuzz)
{
    return kind == PTR_MATERIAL_METAL && fuzz > 0.0f;
}

/* Metal with fuzz: the mirror direction plus ptr_fuzz_offset, absorbed
 * (*scattered 0) where that points into the surface. */
static inline PtrVec3 ptr_scatter_fuzzy_metal(float fuzz, PtrVec3 d, PtrVec3 outward_normal,
                                              const float u[3], int *scattered)
{
    PtrVec3 n = ptr_facing_normal(d, outward_normal);
    PtrVec3 dir = v3_add(ptr_reflect(d, n), ptr_fuzz_offset(fuzz, u));
    *scattered = v3_dot(dir, n) > 0.0f;
    return v3_normalize(dir);
}

/* Whether scattering off a material of this kind may read the third
 * number u[2] (the Fresnel coin, the fuzz radius): where no lane's does,
 * the bundles do not draw it. */
static inline int ptr_scatter_reads_third(PtrMaterialKind kind)
{
    return kind != PTR_MATERIAL_DIFFUSE;
}

/* The factor a path's throughput takes where it scatters off a material of
 * this kind and albedo: the BSDF times the cosine over the density of the
 * direction taken. Every kind here draws its direction in proportion to
 * BSDF times cosine, so the factor is the albedo (for diffuse,
 * ptr_material_eval over ptr_material_pdf). */
static inline PtrVec3 ptr_scatter_attenuation(PtrMaterialKind kind, PtrVec3 albedo)
{
    (void)kind;
    return albedo;
}

/* For diffuse materials, with n the unit normal on the side the light
 * arrives from: the density (per solid angle) with which ptr_scatter picks
 * out_dir, cos / pi, and the BSDF times the cosine, albedo cos / pi. Their
 * ratio is the attenuation ptr_scatter reports, so light sampling and
 * scattering weigh a direction alike (multiple importance sampling). */
static inline float ptr_diffuse_pdf(PtrVec3 n, PtrVec3 out_dir)
{
    return ptr_maxf(0.0f, v3_dot(n, out_dir)) * (1.0f / PTR_PI);
}

static inline PtrVec3 ptr_diffuse_eval(const PtrMaterial *material, PtrVec3 n, PtrVec3 out_dir)
{
    return v3_scale(material->albedo, ptr_diffuse_pdf(n, out_dir));
}

/* Whether the passes see through a material of this kind and fuzz, as a
 * denoiser wants its guides (render/path.h): a perfect mirror or glass. */
static inline int ptr_material_is_see_through(PtrMaterialKind kind, float fuzz)
{
    return kind == PTR_MATERIAL_DIELECTRIC || (kind == PTR_MATERIAL_METAL && fuzz == 0.0f);
}

/* Whether scattering off a material of this kind has a density that light
 * sampling can weigh its directions against (ptr_material_pdf): where it
 * has none (a mirror's or glass's single direction, metal's fuzz), light
 * sampling skips the vertex and the emission scattering finds counts fully. */
static inline int ptr_material_has_density(PtrMaterialKind kind)
{
    return kind == PTR_MATERIAL_DIFFUSE;
}

/* The density with which scattering off material picks out_dir, n the
 * unit normal on the side the light arrives from, and the BSDF times the
 * cosine there: what multiple importance sampling weighs light samples by.
 * Both are 0 for a material without a density. */
static inline float ptr_material_pdf(const PtrMaterial *material, PtrVec3 n, PtrVec3 out_dir)
{
    return material->kind == PTR_MATERIAL_DIFFUSE ? ptr_diffuse_pdf(n, out_dir) : 0.0f;
}

static inline PtrVec3 ptr_material_eval(const PtrMaterial *material, PtrVec3 n, PtrVec3 out_dir)
{
    return material->kind == PTR_MATERIAL_DIFFUSE ? ptr_diffuse_eval(material, n, out_dir)
                                                  : v3_splat(0.0f);
}

#endif /* PTR_MATERIAL_H */
