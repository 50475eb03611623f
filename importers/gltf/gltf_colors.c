/* Spheres coloured by their vertices (gltf_colors.h). */
#include "gltf_colors.h"

#include <stdio.h>
#include <stdlib.h>

#include "base/cpu.h"
#include "base/threads.h"
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
static PtrResult vertex_values(GltfTextures *textures, const VertexColors *vc, size_t v,
                               float out[VALUES], PtrError *err)
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
        PtrResult res = gltf_textures_sample(textures, vc->refs[r], e,
                                             r == 2 ? GLTF_TEXELS_STORED : GLTF_TEXELS_LINEAR,
                                             texel, err);
        if (res != PTR_OK)
            return res;
        if (r == 2) {
            out[6] = texel[2];
            out[7] = texel[1];
        } else {
            for (int k = 0; k < 3; k++)
                out[3 * r + k] *= texel[k];
        }
    }
    return PTR_OK;
}

/* The part's vertices whose values are summed: those of sphere components
 * whose material is the part's (their first triangle in it). */
typedef struct PartVertices {
    const SurfaceParts *s;
    const SurfacePart *part;
    const PtrMeshSphere *found;
    const uint32_t *labels;
} PartVertices;

/* Vertex v's component (v from the part's first), or UINT32_MAX where its
 * values are not summed. */
static uint32_t summed_component(const PartVertices *pv, size_t v)
{
    const uint32_t c = pv->labels[pv->part->first_vertex + v];
    if (c == UINT32_MAX || !pv->found[c].is_sphere ||
        gltf_part_of(pv->s, pv->found[c].first_triangle, 1) != pv->part)
        return UINT32_MAX;
    return c;
}

static void add_values(ColorSum *sum, const float values[VALUES])
{
    for (int k = 0; k < VALUES; k++) {
        if (!sum->vertices)
            sum->first[k] = values[k];
        sum->varies |= fabsf(values[k] - sum->first[k]) > 1e-6f;
        sum->sum[k] += values[k];
    }
    sum->vertices++;
}

/* A part of this many vertices or more has its values read on all cores,
 * COLOR_BLOCK vertices at a time; they are then added in the vertices'
 * order, so that the sums do not depend on how many threads read them. */
enum { PARALLEL_COLORS = 1 << 15, COLOR_BLOCK = 1 << 18 };

/* The values of a block of a part's vertices, read on all cores. */
typedef struct BlockValues {
    const PartVertices *vertices;
    GltfTextures *textures;
    const VertexColors *vc;
    size_t first;            /* the block's first vertex */
    float (*values)[VALUES]; /* each summed vertex's, from the block's first */
    atomic_size_t failed;    /* the least vertex whose values fail; SIZE_MAX: none */
} BlockValues;

/* Reads the values of vertices from .. to - 1 of the block; the textures
 * they sample are decoded already, so that threads only read them. */
static void read_values(void *arg, size_t from, size_t to)
{
    BlockValues *b = arg;
    for (size_t v = from; v < to; v++)
        if (summed_component(b->vertices, v) != UINT32_MAX &&
            vertex_values(b->textures, b->vc, v, b->values[v - b->first], NULL) != PTR_OK) {
            gltf_note_failure(&b->failed, v);
            return;
        }
}

/* Adds the part's summed vertices to the sums of their components. */
static PtrResult add_part_colors(Importer *im, const Origin *o, size_t mesh_index,
                                 const PartVertices *pv, ColorSum *sums)
{
    GltfPrimitive prim;
    GltfMaterial g;
    gltf_doc_primitive(im->doc, mesh_index, (size_t)pv->part->primitive, &prim);
    if (!gltf_colored_by_vertices(im, &prim))
        return PTR_OK;
    gltf_primitive_material(im, &prim, &g);
    VertexColors vc;
    PtrResult res = vertex_colors(im, o, mesh_index, pv->part, &prim, &g, &vc);
    const size_t count = pv->part->pos.count;
    size_t v = 0;
    while (v < count && summed_component(pv, v) == UINT32_MAX)
        v++;
    /* The first summed vertex read here decodes the textures the part
     * reads, or fails as a serial read does. */
    float values[VALUES];
    if (res != PTR_OK || v == count ||
        (res = vertex_values(im->textures, &vc, v, values, im->err)) != PTR_OK)
        return res;
    BlockValues b = { .vertices = pv, .textures = im->textures, .vc = &vc,
                      .values = malloc((count - v < COLOR_BLOCK ? count - v : COLOR_BLOCK) *
                                       sizeof *b.values) };
    if (!b.values)
        return ptr_error_set(im->err, PTR_ERR_NOMEM, "%s: out of memory", im->path);
    const int threads = count >= PARALLEL_COLORS ? ptr_usable_cpus() : 1;
    for (; v < count && res == PTR_OK; v = b.first + COLOR_BLOCK) {
        b.first = v;
        const size_t end = count - v > COLOR_BLOCK ? v + COLOR_BLOCK : count;
        atomic_store(&b.failed, SIZE_MAX);
        ptr_parallel_ranges(threads, v, end, read_values, &b);
        const size_t failed = atomic_load(&b.failed);
        for (size_t u = v; u < end && res == PTR_OK; u++) {
            const uint32_t c = summed_component(pv, u);
            if (u == failed) /* read again for its message */
                res = vertex_values(im->textures, &vc, u, values, im->err);
            else if (c != UINT32_MAX)
                add_values(&sums[c], b.values[u - v]);
        }
    }
    free(b.values);
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
    for (size_t p = 0; p < s->count && res == PTR_OK; p++) {
        const PartVertices pv = { s, &s->parts[p], found, labels };
        res = add_part_colors(im, o, mesh_index, &pv, sums);
    }
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
