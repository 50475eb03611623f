/* Scattering at a surface, as the seed's renderer models it: Lambertian
 * diffuse, metal with fuzz, and dielectric with Fresnel (Schlick)
 * reflect-or-refract and total internal reflection. */
#ifndef PTR_MATERIAL_H
#define PTR_MATERIAL_H

#include "core/scene.h"

/* Samples an outgoing direction for a ray arriving along unit in_dir at a
 * surface whose outward unit normal is outward_normal, from three uniform
 * numbers in [0, 1): u[0] and u[1] pick a direction, u[2] the Fresnel choice
 * of glass or the fuzz radius of metal. On return *out_dir is a unit vector
 * and *attenuation the factor the path's throughput takes (the BSDF times
 * the cosine over the density of the direction). Returns 0 if the ray is
 * absorbed (a fuzzed metal ray pointing into the surface). */
int ptr_scatter(const PtrMaterial *material, PtrVec3 in_dir, PtrVec3 outward_normal,
                const float u[3], PtrVec3 *out_dir, PtrVec3 *attenuation);

/* For diffuse materials, with n the unit normal on the side the light
 * arrives from: the density (per solid angle) with which ptr_scatter picks
 * out_dir, cos / pi, and the BSDF times the cosine, albedo cos / pi. Their
 * ratio is the attenuation ptr_scatter reports, so light sampling and
 * scattering weigh a direction alike (multiple importance sampling). */
float ptr_diffuse_pdf(PtrVec3 n, PtrVec3 out_dir);
PtrVec3 ptr_diffuse_eval(const PtrMaterial *material, PtrVec3 n, PtrVec3 out_dir);

/* A uniformly distributed unit vector from two uniform numbers. */
PtrVec3 ptr_uniform_sphere(const float u[2]);

/* Schlick's approximation of Fresnel reflectance for the cosine of the angle
 * of incidence and the ratio of refractive indices (incident / transmitted). */
float ptr_schlick(float cosine, float eta_ratio);

/* Mirror reflection of d about the unit normal n. */
static inline PtrVec3 ptr_reflect(PtrVec3 d, PtrVec3 n)
{
    return v3_sub(d, v3_scale(n, 2.0f * v3_dot(d, n)));
}

#endif /* PTR_MATERIAL_H */
