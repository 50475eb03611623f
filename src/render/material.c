#include "render/material.h"

/* The direction of ptr_scatter_direction, its kind a constant: inlined into
 * each case below, it computes that kind's direction alone. */
#define SCATTER_AS(kind)                                                                     \
    ptr_scatter_direction(kind, material->ior, in_dir, outward_normal, u, &scattered)

int ptr_scatter(const PtrMaterial *material, PtrVec3 in_dir, PtrVec3 outward_normal,
                const float u[3], PtrVec3 *out_dir, PtrVec3 *attenuation)
{
    int scattered;
    *attenuation = ptr_scatter_attenuation(material->kind, material->albedo);
    if (ptr_scatter_is_fuzzy(material->kind, material->fuzz)) {
        *out_dir = ptr_scatter_fuzzy_metal(material->fuzz, in_dir, outward_normal, u, &scattered);
        return scattered;
    }
    switch (material->kind) {
    case PTR_MATERIAL_DIFFUSE: *out_dir = SCATTER_AS(PTR_MATERIAL_DIFFUSE); break;
    case PTR_MATERIAL_METAL: *out_dir = SCATTER_AS(PTR_MATERIAL_METAL); break;
    case PTR_MATERIAL_DIELECTRIC: *out_dir = SCATTER_AS(PTR_MATERIAL_DIELECTRIC); break;
    default: *out_dir = SCATTER_AS(material->kind); break;
    }
    return scattered;
}
