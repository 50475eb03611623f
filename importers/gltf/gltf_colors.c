/* Spheres coloured by their vertices (gltf_colors.h). */
#include "gltf_colors.h"

#include <stdio.h>
#include <stdlib.h>

#include "gltf_accessors.h"
#include "gltf_materials.h"

int gltf_colored_by_vertices(const Importer *im, const GltfPrimitive *prim)
{
    GltfMaterial g;
    gltf_primitive_material(im, prim, &g);
    return prim->color >= 0 || (im->textures && gltf_has_color_texture(&g));
}

/* What the vertices of one component read: each value's sum over them, the
 * first vertex's values and whether another differs. */
enum { VALUES = 8 }; /* base r g b, emission r g b, metallic, roughness */
typedef struct ColorSum {
    double sum[VALUES];
    float first[VALUES];
    size_t vertices;
    int varies;
} ColorSum;

/* The texture references of a material, the TEXCOORD accessors they read
 * (one a reference, checked) and the part's COLOR_0. */
typedef struct VertexColors {
    const GltfTextureRef *refs[3]; /* base, emissive, metallic-roughness; NULL: none */
    GltfAccessor uv[3], color;
    int has_color;
} VertexColors;

static PtrResult vertex_colors(Importer *im, const Origin *o, size_t mesh_index,
                               const SurfacePart *part, const GltfPrimitive *prim,
                               const GltfMaterial *g, VertexColors *vc)
{
    const GltfTextureRef *refs[3] = { &g->base_texture, &g->emissive_texture,
                                      &g->metal_rough_texture };
    PtrResult res = PTR_OK;
    size_t count = part->pos.count;
    for (int r = 0; r < 3 && res == PTR_OK; r++) {
        vc->refs[r] = im->textures && refs[r]->texture >= 0 ? refs[r] : NULL;
        if (!vc->refs[r])
            continue;
        char name[32];
        snprintf(name, sizeof name, "TEXCOORD_%d", refs[r]->texcoord);
        const int index = gltf_doc_primitive_attribute(im->doc, mesh_index,
                                                       (size_t)part->primitive, name);
        if (index < 0)
            return ptr_error_set(im->err, PTR_ERR_SCENE_INVALID,
                                 "%s: mesh %zu primitive %d: its material's texture %d reads %s, "
                                 "which the primitive does not have", im->path, mesh_index,
                                 part->primitive, refs[r]->texture, name);
        res = gltf_attribute_accessor(im, o, name, index, 2, 2, QUANTIZED, &count, &vc->uv[r]);
    }
    vc->has_color = prim->color >= 0;
    if (res == PTR_OK && vc->has_color)
        res = gltf_attribute_accessor(im, o, "COLOR_0", prim->color, 3, 4, FLOATS_OR_UNSIGNED,
                                      &count, &vc->color);
    return res;
}

/* Vertex v's values (see ColorSum): COLOR_0 times the linear base colour
 * texel, the linear emissive texel, the metallic-roughness texel's B and G;
 * 1 where there is none. */
static PtrResult vertex_values(Importer *im, const VertexColors *vc, size_t v,
                               float out[VALUES])
{
    for (int k = 0; k < VALUES; k++)
        out[k] = 1.0f;
    double e[4];
    if (vc->has_color) {
        gltf_element(&vc->color, v, e);
        for (int k = 0; k < 3; k++)
            out[k] = (float)e[k];
    }
    for (int r = 0; r < 3; r++) {
        if (!vc->refs[r])
            continue;
        float texel[4];
        gltf_element(&vc->uv[r], v, e);
        PtrResult res = gltf_textures_sample(im->textures, vc->refs[r], e, texel, im->err);
        if (res != PTR_OK)
            return res;
        if (r == 2) {
            out[6] = texel[2];
            out[7] = texel[1];
        } else {
            for (int k = 0; k < 3; k++)
                out[3 * r + k] *= (float)gltf_srgb_to_linear(texel[k]);
        }
    }
    return PTR_OK;
}

/* Adds the part's vertices to the sums of the components they belong to,
 * those whose material is the part's (their first triangle in it). */
static PtrResult add_part_colors(Importer *im, const Origin *o, size_t mesh_index,
                                 const SurfaceParts *s, const SurfacePart *part,
                                 const PtrMeshSphere *found, const uint32_t *labels,
                                 ColorSum *sums)
{
    GltfPrimitive prim;
    GltfMaterial g;
    gltf_doc_primitive(im->doc, mesh_index, (size_t)part->primitive, &prim);
    if (!gltf_colored_by_vertices(im, &prim))
        return PTR_OK;
    gltf_primitive_material(im, &prim, &g);
    VertexColors vc;
    PtrResult res = vertex_colors(im, o, mesh_index, part, &prim, &g, &vc);
    for (size_t v = 0; v < part->pos.count && res == PTR_OK; v++) {
        const uint32_t c = labels[part->first_vertex + v];
        if (c == UINT32_MAX || !found[c].is_sphere ||
            gltf_part_of(s, found[c].first_triangle, 1) != part)
            continue;
        float values[VALUES];
        res = vertex_values(im, &vc, v, values);
        ColorSum *sum = &sums[c];
        for (int k = 0; k < VALUES && res == PTR_OK; k++) {
            if (!sum->vertices)
                sum->first[k] = values[k];
            sum->varies |= fabsf(values[k] - sum->first[k]) > 1e-6f;
            sum->sum[k] += values[k];
        }
        sum->vertices++;
    }
    return res;
}

/* Component c's material, from the sums over its vertices: the factors
 * times the means (docs/scenes.md, "Textures"). */
static PtrResult component_material(Importer *im, size_t mesh_index, const SurfaceParts *s,
                                    const PtrMeshSphere *found, size_t c, const ColorSum *sum,
                                    uint32_t *out)
{
    GltfPrimitive prim;
    GltfMaterial g;
    gltf_doc_primitive(im->doc, mesh_index,
                       (size_t)gltf_part_of(s, found[c].first_triangle, 1)->primitive, &prim);
    gltf_primitive_material(im, &prim, &g);
    MaterialValues v = gltf_factor_values(&g);
    const double n = (double)sum->vertices;
    for (int k = 0; k < 3; k++) {
        v.base[k] *= sum->sum[k] / n;
        v.emission[k] *= sum->sum[3 + k] / n;
    }
    v.metallic *= sum->sum[6] / n;
    v.roughness *= sum->sum[7] / n;
    im->varying += sum->varies;
    PtrMaterial m;
    PtrResult res = gltf_convert_material(im, prim.material, &g, &v, &m);
    return res == PTR_OK ? gltf_made_material(im, &m, out) : res;
}

PtrResult gltf_surface_colors(Importer *im, const Origin *o, size_t mesh_index,
                              const SurfaceParts *s, const PtrMeshSphere *found,
                              size_t components, const uint32_t *labels, SurfaceSpheres *out)
{
    ColorSum *sums = calloc(components ? components : 1, sizeof *sums);
    out->materials = malloc((out->count ? out->count : 1) * sizeof *out->materials);
    if (!sums || !out->materials) {
        free(sums);
        return ptr_error_set(im->err, PTR_ERR_NOMEM, "%s: out of memory", im->path);
    }
    PtrResult res = PTR_OK;
    for (size_t p = 0; p < s->count && res == PTR_OK; p++)
        res = add_part_colors(im, o, mesh_index, s, &s->parts[p], found, labels, sums);
    for (size_t c = 0, k = 0; c < components && res == PTR_OK; c++) {
        if (!found[c].is_sphere)
            continue;
        out->materials[k] = UINT32_MAX;
        if (sums[c].vertices)
            res = component_material(im, mesh_index, s, found, c, &sums[c],
                                     &out->materials[k]);
        k++;
    }
    free(sums);
    return res;
}
