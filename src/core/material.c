#include "core/material.h"

#include <math.h>

/* A uniformly distributed unit vector from two uniform numbers. */
static PtrVec3 unit_vector(float u0, float u1)
{
    /* Archimedes: z is uniform on [-1, 1] for a uniform point on the sphere. */
    float z = 1.0f - 2.0f * u0;
    float r = sqrtf(ptr_maxf(0.0f, 1.0f - z * z));
    float phi = 2.0f * PTR_PI * u1;
    return v3(r * cosf(phi), r * sinf(phi), z);
}

PtrVec3 ptr_uniform_sphere(const float u[2])
{
    return unit_vector(u[0], u[1]);
}

float ptr_schlick(float cosine, float eta_ratio)
{
    float r0 = (1.0f - eta_ratio) / (1.0f + eta_ratio);
    r0 = r0 * r0;
    float m = 1.0f - cosine;
    return r0 + (1.0f - r0) * (m * m) * (m * m) * m;
}

/* The normal plus a uniform unit vector is cosine-distributed about the
 * normal: the density ptr_diffuse_pdf gives. */
static PtrVec3 scatter_diffuse(PtrVec3 n, const float u[3])
{
    PtrVec3 dir = v3_add(n, unit_vector(u[0], u[1]));
    /* The sample can cancel the normal; fall back to it then. */
    if (v3_max_abs(dir) < 1e-6f)
        return n;
    return v3_normalize(dir);
}

static PtrVec3 scatter_dielectric(const PtrMaterial *m, PtrVec3 d, PtrVec3 n,
                                  int entering, float u)
{
    float eta_ratio = entering ? 1.0f / m->ior : m->ior;
    float cos_theta = ptr_minf(-v3_dot(d, n), 1.0f);
    float sin_theta = sqrtf(ptr_maxf(0.0f, 1.0f - cos_theta * cos_theta));
    int total_internal = eta_ratio * sin_theta > 1.0f;
    if (total_internal || ptr_schlick(cos_theta, eta_ratio) > u)
        return ptr_reflect(d, n);

    PtrVec3 perp = v3_scale(v3_madd(d, n, cos_theta), eta_ratio);
    float parallel = -sqrtf(fabsf(1.0f - v3_dot(perp, perp)));
    return v3_normalize(v3_madd(perp, n, parallel));
}

int ptr_scatter(const PtrMaterial *material, PtrVec3 in_dir, PtrVec3 outward_normal,
                const float u[3], PtrVec3 *out_dir, PtrVec3 *attenuation)
{
    int entering = v3_dot(in_dir, outward_normal) < 0.0f;
    PtrVec3 n = entering ? outward_normal : v3_neg(outward_normal);
    *attenuation = material->albedo;

    switch (material->kind) {
    case PTR_MATERIAL_DIFFUSE:
        *out_dir = scatter_diffuse(n, u);
        return 1;
    case PTR_MATERIAL_METAL: {
        PtrVec3 dir = ptr_reflect(in_dir, n);
        if (material->fuzz > 0.0f) {
            /* A uniform point in the unit ball: uniform direction, radius
             * the cube root of a uniform number. */
            PtrVec3 ball = v3_scale(unit_vector(u[0], u[1]), cbrtf(u[2]));
            dir = v3_add(dir, v3_scale(ball, material->fuzz));
        }
        if (!(v3_dot(dir, n) > 0.0f))
            return 0;
        *out_dir = v3_normalize(dir);
        return 1;
    }
    case PTR_MATERIAL_DIELECTRIC:
        *out_dir = scatter_dielectric(material, in_dir, n, entering, u[2]);
        return 1;
    }
    return 0;
}

float ptr_diffuse_pdf(PtrVec3 n, PtrVec3 out_dir)
{
    return ptr_maxf(0.0f, v3_dot(n, out_dir)) * (1.0f / PTR_PI);
}

PtrVec3 ptr_diffuse_eval(const PtrMaterial *material, PtrVec3 n, PtrVec3 out_dir)
{
    return v3_scale(material->albedo, ptr_diffuse_pdf(n, out_dir));
}
