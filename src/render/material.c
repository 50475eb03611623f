#include "render/material.h"

/* The direction of ptr_scatter_direction, its kind a constant: inlined into
 * each case below, it computes that kind's direction alone. */
#define SCATTER_AS(kind)                                                                     \
    ptr_scatter_direction(kind, material->ior, in_dir, n, entering, u, &scattered)

int ptr_scatter(const PtrMaterial *material, PtrVec3 in_dir, PtrVec3 outward_normal,
                const float u[3], PtrVec3 *out_dir, PtrVec3 *attenuation)
{
    int entering = v3_dot(in_dir, outward_normal) < 0.0f, scattered;
    PtrVec3 n = ptr_facing_normal(in_dir, outward_normal);
    *attenuation = material->albedo;
    switch (material->kind) {
    case PTR_MATERIAL_DIFFUSE: *out_dir = SCATTER_AS(PTR_MATERIAL_DIFFUSE); break;
    case PTR_MATERIAL_METAL:
        *out_dir = material->fuzz > 0.0f
                       ? ptr_scatter_fuzzy_metal(material->fuzz, in_dir, n, u, &scattered)
                       : SCATTER_AS(PTR_MATERIAL_METAL);
        break;
    case PTR_MATERIAL_DIELECTRIC: *out_dir = SCATTER_AS(PTR_MATERIAL_DIELECTRIC); break;
    default: *out_dir = SCATTER_AS(material->kind); break;
    }
    return scattered;
}
