/* Scattering at a surface, as the seed's renderer models it: Lambertian
 * diffuse, metal with fuzz, and dielectric with Fresnel (Schlick)
 * reflect-or-refract and total internal reflection. */
#ifndef PTR_MATERIAL_H
#define PTR_MATERIAL_H

#include "sampling/rng.h"
#include "core/scene.h"

/* Samples an outgoing direction for a ray arriving along unit in_dir at a
 * surface whose outward unit normal is outward_normal. On return *out_dir is a
 * unit vector and *attenuation the factor the path's throughput takes.
 * Returns 0 if the ray is absorbed (a fuzzed metal ray pointing into the
 * surface). */
int ptr_scatter(const PtrMaterial *material, PtrVec3 in_dir, PtrVec3 outward_normal,
                PtrRng *rng, PtrVec3 *out_dir, PtrVec3 *attenuation);

/* Schlick's approximation of Fresnel reflectance for the cosine of the angle
 * of incidence and the ratio of refractive indices (incident / transmitted). */
float ptr_schlick(float cosine, float eta_ratio);

/* Mirror reflection of d about the unit normal n. */
static inline PtrVec3 ptr_reflect(PtrVec3 d, PtrVec3 n)
{
    return v3_sub(d, v3_scale(n, 2.0f * v3_dot(d, n)));
}

#endif /* PTR_MATERIAL_H */
