#include "core/material.h"

#include <math.h>

/* A uniformly distributed unit vector. */
static PtrVec3 random_unit_vector(PtrRng *rng)
{
    /* Archimedes: z is uniform on [-1, 1] for a uniform point on the sphere.
     * No rejection loop, so every sample uses the same count of numbers. */
    float z = 1.0f - 2.0f * ptr_rng_float(rng);
    float r = sqrtf(ptr_maxf(0.0f, 1.0f - z * z));
    float phi = 2.0f * PTR_PI * ptr_rng_float(rng);
    return v3(r * cosf(phi), r * sinf(phi), z);
}

static PtrVec3 random_in_unit_ball(PtrRng *rng)
{
    PtrVec3 dir = random_unit_vector(rng);
    return v3_scale(dir, cbrtf(ptr_rng_float(rng)));
}

float ptr_schlick(float cosine, float eta_ratio)
{
    float r0 = (1.0f - eta_ratio) / (1.0f + eta_ratio);
    r0 = r0 * r0;
    float m = 1.0f - cosine;
    return r0 + (1.0f - r0) * (m * m) * (m * m) * m;
}

static PtrVec3 scatter_diffuse(PtrVec3 n, PtrRng *rng)
{
    PtrVec3 dir = v3_add(n, random_unit_vector(rng));
    /* The sample can cancel the normal; fall back to it then. */
    if (v3_max_abs(dir) < 1e-6f)
        return n;
    return v3_normalize(dir);
}

static PtrVec3 scatter_dielectric(const PtrMaterial *m, PtrVec3 d, PtrVec3 n,
                                  int entering, PtrRng *rng)
{
    float eta_ratio = entering ? 1.0f / m->ior : m->ior;
    float cos_theta = ptr_minf(-v3_dot(d, n), 1.0f);
    float sin_theta = sqrtf(ptr_maxf(0.0f, 1.0f - cos_theta * cos_theta));
    int total_internal = eta_ratio * sin_theta > 1.0f;
    if (total_internal || ptr_schlick(cos_theta, eta_ratio) > ptr_rng_float(rng))
        return ptr_reflect(d, n);

    PtrVec3 perp = v3_scale(v3_madd(d, n, cos_theta), eta_ratio);
    float parallel = -sqrtf(fabsf(1.0f - v3_dot(perp, perp)));
    return v3_normalize(v3_madd(perp, n, parallel));
}

int ptr_scatter(const PtrMaterial *material, PtrVec3 in_dir, PtrVec3 outward_normal,
                PtrRng *rng, PtrVec3 *out_dir, PtrVec3 *attenuation)
{
    int entering = v3_dot(in_dir, outward_normal) < 0.0f;
    PtrVec3 n = entering ? outward_normal : v3_neg(outward_normal);
    *attenuation = material->albedo;

    switch (material->kind) {
    case PTR_MATERIAL_DIFFUSE:
        *out_dir = scatter_diffuse(n, rng);
        return 1;
    case PTR_MATERIAL_METAL: {
        PtrVec3 dir = ptr_reflect(in_dir, n);
        if (material->fuzz > 0.0f)
            dir = v3_add(dir, v3_scale(random_in_unit_ball(rng), material->fuzz));
        if (!(v3_dot(dir, n) > 0.0f))
            return 0;
        *out_dir = v3_normalize(dir);
        return 1;
    }
    case PTR_MATERIAL_DIELECTRIC:
        *out_dir = scatter_dielectric(material, in_dir, n, entering, rng);
        return 1;
    }
    return 0;
}
