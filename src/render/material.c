#include "render/material.h"

int ptr_scatter(const PtrMaterial *material, PtrVec3 in_dir, PtrVec3 outward_normal,
                const float u[3], PtrVec3 *out_dir, PtrVec3 *attenuation)
{
    int entering = v3_dot(in_dir, outward_normal) < 0.0f;
    PtrVec3 n = entering ? outward_normal : v3_neg(outward_normal);
    *attenuation = material->albedo;

    switch (material->kind) {
    case PTR_MATERIAL_DIFFUSE:
        *out_dir = ptr_scatter_diffuse(n, u[0], u[1]);
        return 1;
    case PTR_MATERIAL_METAL: {
        PtrVec3 dir = ptr_reflect(in_dir, n);
        if (material->fuzz > 0.0f)
            dir = v3_add(dir, ptr_fuzz_offset(material->fuzz, u));
        if (!(v3_dot(dir, n) > 0.0f))
            return 0;
        *out_dir = v3_normalize(dir);
        return 1;
    }
    case PTR_MATERIAL_DIELECTRIC:
        *out_dir = ptr_scatter_dielectric(material->ior, in_dir, n, entering, u[2]);
        return 1;
    }
    return 0;
}
