/* glTF materials as the scene's (gltf_materials.h). */
#include "gltf_materials.h"

#include <stdlib.h>
#include <string.h>

int gltf_has_color_texture(const GltfMaterial *g)
{
    return g->base_texture.texture >= 0 || g->emissive_texture.texture >= 0 ||
           g->metal_rough_texture.texture >= 0;
}

MaterialValues gltf_factor_values(const GltfMaterial *g)
{
    MaterialValues v = { .metallic = g->metallic, .roughness = g->roughness };
    for (int k = 0; k < 3; k++) {
        v.base[k] = g->base_color[k];
        v.emission[k] = g->emissive[k] * g->emissive_strength;
    }
    return v;
}

PtrResult gltf_convert_material(Importer *im, int gltf_index, const GltfMaterial *g,
                                const MaterialValues *v, PtrMaterial *m)
{
    /* The factors the material does not keep; ptr_material_problem checks
     * the rest once converted. */
    if (!all_finite(g->base_color, 4) || !isfinite(g->ior) || !isfinite(v->roughness) ||
        !isfinite(v->metallic) || !isfinite(g->transmission) || !(g->ior > 0.0))
        return ptr_error_set(im->err, PTR_ERR_SCENE_INVALID,
                             "%s: material %d ('%s') has a value out of range", im->path,
                             gltf_index, label(g->name, "unnamed"));
    *m = (PtrMaterial){ .kind = PTR_MATERIAL_DIFFUSE, .albedo = vec_from(v->base),
                        .emission = vec_from(v->emission), .ior = 1.5f };
    if (g->transmission > 0.0) {
        m->kind = PTR_MATERIAL_DIELECTRIC;
        m->ior = (float)g->ior;
    } else if (v->metallic >= 0.5) {
        m->kind = PTR_MATERIAL_METAL;
        m->fuzz = (float)v->roughness;
    }
    const char *problem = ptr_material_problem(m);
    if (problem)
        return ptr_error_set(im->err, PTR_ERR_SCENE_INVALID, "%s: material %d ('%s'): %s",
                             im->path, gltf_index, label(g->name, "unnamed"), problem);
    return PTR_OK;
}

static PtrResult add_material(Importer *im, const PtrMaterial *m, uint32_t *out)
{
    if (ptr_scene_add_material(im->scene, m, out, NULL) != PTR_OK)
        return ptr_error_set(im->err, PTR_ERR_NOMEM, "%s: out of memory", im->path);
    return PTR_OK;
}

PtrResult gltf_map_material(Importer *im, int gltf_index, uint32_t *out)
{
    uint32_t *slot = gltf_index < 0 ? &im->default_material : &im->material_index[gltf_index];
    if (*slot != UINT32_MAX) {
        *out = *slot;
        return PTR_OK;
    }
    PtrMaterial m = { .kind = PTR_MATERIAL_DIFFUSE, .albedo = v3_splat(0.8f), .ior = 1.5f };
    if (gltf_index >= 0) {
        GltfMaterial g;
        gltf_doc_material(im->doc, (size_t)gltf_index, &g);
        if (gltf_has_color_texture(&g) && !im->warned_texture) {
            im->warned_texture = 1;
            ptr_warn(im->warnings, "%s: textures are ignored without an image reader or "
                     "vertices to read them at (first seen on material '%s')", im->path,
                     label(g.name, "unnamed"));
        }
        const MaterialValues v = gltf_factor_values(&g);
        PtrResult res = gltf_convert_material(im, gltf_index, &g, &v, &m);
        if (res != PTR_OK)
            return res;
    }
    PtrResult res = add_material(im, &m, slot);
    *out = *slot;
    return res;
}

/* FNV-1a over a material's bytes (floats and an enum: no padding). */
static size_t material_hash(const PtrMaterial *m)
{
    const unsigned char *b = (const unsigned char *)m;
    uint64_t h = 0xcbf29ce484222325u;
    for (size_t i = 0; i < sizeof *m; i++)
        h = (h ^ b[i]) * 0x100000001b3u;
    return (size_t)h;
}

PtrResult gltf_made_material(Importer *im, const PtrMaterial *m, uint32_t *out)
{
    if (2 * (im->made_count + 1) > im->made_slots) { /* grown, the table made again */
        const size_t slots = im->made_slots ? 2 * im->made_slots : 64;
        uint32_t *table = malloc(slots * sizeof *table);
        if (!table)
            return ptr_error_set(im->err, PTR_ERR_NOMEM, "%s: out of memory", im->path);
        memset(table, 0xff, slots * sizeof *table);
        for (size_t i = 0; i < im->made_slots; i++) {
            if (im->made[i] == UINT32_MAX)
                continue;
            size_t at = material_hash(&im->scene->materials[im->made[i]]) & (slots - 1);
            while (table[at] != UINT32_MAX)
                at = (at + 1) & (slots - 1);
            table[at] = im->made[i];
        }
        free(im->made);
        im->made = table;
        im->made_slots = slots;
    }
    const size_t mask = im->made_slots - 1;
    size_t at = material_hash(m) & mask;
    for (; im->made[at] != UINT32_MAX; at = (at + 1) & mask)
        if (!memcmp(&im->scene->materials[im->made[at]], m, sizeof *m)) {
            *out = im->made[at];
            return PTR_OK;
        }
    PtrResult res = add_material(im, m, &im->made[at]);
    im->made_count += res == PTR_OK;
    *out = im->made[at];
    return res;
}

void gltf_primitive_material(const Importer *im, const GltfPrimitive *prim, GltfMaterial *g)
{
    if (prim->material >= 0) {
        gltf_doc_material(im->doc, (size_t)prim->material, g);
        return;
    }
    *g = (GltfMaterial){ .base_color = { 0.8, 0.8, 0.8, 1 }, .roughness = 1,
                         .emissive_strength = 1, .ior = 1.5,
                         .base_texture.texture = -1, .emissive_texture.texture = -1,
                         .metal_rough_texture.texture = -1 };
}
