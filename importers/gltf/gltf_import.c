/* glTF nodes to spheres, following docs/scenes.md. */
#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "base/cpu.h"
#include "base/threads.h"
#include "builder.h"
#include "gltf_doc.h"
#include "gltf_textures.h"
#include "importer_internal.h"
#include "mesh_spheres.h"

enum { MAX_RESOLUTION = 1 << 16 };

/* 4x4 affine transforms, column-major like glTF: m[column * 4 + row]. */
typedef struct Mat4 {
    double m[16];
} Mat4;

static Mat4 mat4_mul(const Mat4 *a, const Mat4 *b)
{
    Mat4 r;
    for (int c = 0; c < 4; c++)
        for (int row = 0; row < 4; row++) {
            double sum = 0.0;
            for (int k = 0; k < 4; k++)
                sum += a->m[k * 4 + row] * b->m[c * 4 + k];
            r.m[c * 4 + row] = sum;
        }
    return r;
}

/* T * R * S, as glTF composes a node's TRS properties (rotation a unit
 * quaternion x, y, z, w). */
static Mat4 trs_matrix(const double translation[3], const double rotation[4],
                       const double scale[3])
{
    Mat4 r;
    const double x = rotation[0], y = rotation[1], z = rotation[2], w = rotation[3];
    const double rot[9] = {
        1 - 2 * (y * y + z * z), 2 * (x * y + z * w), 2 * (x * z - y * w),
        2 * (x * y - z * w), 1 - 2 * (x * x + z * z), 2 * (y * z + x * w),
        2 * (x * z + y * w), 2 * (y * z - x * w), 1 - 2 * (x * x + y * y),
    };
    for (int c = 0; c < 3; c++) {
        for (int row = 0; row < 3; row++)
            r.m[c * 4 + row] = rot[c * 3 + row] * scale[c];
        r.m[c * 4 + 3] = 0.0;
    }
    r.m[12] = translation[0];
    r.m[13] = translation[1];
    r.m[14] = translation[2];
    r.m[15] = 1.0;
    return r;
}

static Mat4 node_local(const GltfNode *n)
{
    if (!n->has_matrix)
        return trs_matrix(n->translation, n->rotation, n->scale);
    Mat4 r;
    memcpy(r.m, n->matrix, sizeof r.m);
    return r;
}

static void mat4_point(const Mat4 *a, const double p[3], double out[3])
{
    for (int row = 0; row < 3; row++)
        out[row] = a->m[row] * p[0] + a->m[4 + row] * p[1] + a->m[8 + row] * p[2] +
                   a->m[12 + row];
}

static double column_length(const Mat4 *a, int c)
{
    const double *v = &a->m[c * 4];
    return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

static int all_finite(const double *v, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!isfinite(v[i]))
            return 0;
    return 1;
}

static PtrVec3 vec_from(const double v[3])
{
    return v3((float)v[0], (float)v[1], (float)v[2]);
}

/* A mesh's surface spheres (docs/scenes.md "Spheres"), found once however
 * many nodes use the mesh, and once for meshes of the same surface. */
typedef struct SurfaceSpheres {
    int found;
    const struct SurfaceSpheres *same; /* where the spheres are: itself, or
                                        * an earlier mesh's; NULL until found */
    size_t count;
    double *spheres;  /* 4 a sphere: the centre and radius in the mesh's frame */
    int *primitives;  /* each one's primitive in its mesh (which gives its material) */
    uint32_t *materials; /* each one's scene material, where textures or vertex
                          * colours give it one of its own; else NULL */
    size_t skipped;   /* the parts that are not spheres */
} SurfaceSpheres;

typedef struct Importer {
    const char *path;
    const GltfDoc *doc;
    PtrScene *scene;
    PtrSceneBuilder builder;
    PtrStrings *warnings;
    PtrError *err;
    const char *camera_name;
    int camera_found;
    const char *ortho_name; /* the orthographic camera taken, if one was */
    double zfar;            /* its far plane */
    uint32_t *material_index; /* glTF material -> scene material, UINT32_MAX unset */
    uint32_t default_material;
    int warned_texture;
    GltfTextures *textures;   /* NULL where the import reads none */
    uint32_t *made;           /* the materials textures gave, by value
                               * (made_slots, a power of two), UINT32_MAX: none */
    size_t made_slots, made_count;
    size_t varying;           /* spheres a texture or COLOR_0 varies over */
    const char *value_name; /* the attribute --color-by asks for, or NULL */
    SurfaceSpheres *surfaces; /* one a mesh */
    size_t *surface_table;    /* meshes by their surface (surface_key), SIZE_MAX: none */
    size_t surface_slots;     /* a power of two */
    size_t skipped;           /* mesh parts not drawn, for the one warning */
    char skipped_names[256];  /* where they are, as many as fit */
    int skipped_more;         /* whether more did not fit */
} Importer;

static const char *label(const char *name, const char *fallback)
{
    return name && *name ? name : fallback;
}

/* Whether a material takes a value from a texture. */
static int has_color_texture(const GltfMaterial *g)
{
    return g->base_texture.texture >= 0 || g->emissive_texture.texture >= 0 ||
           g->metal_rough_texture.texture >= 0;
}

/* What a sphere reads of its material where textures and vertex colours
 * may change it: the factors times their means (docs/scenes.md). */
typedef struct MaterialValues {
    double base[3], emission[3], metallic, roughness;
} MaterialValues;

static MaterialValues factor_values(const GltfMaterial *g)
{
    MaterialValues v = { .metallic = g->metallic, .roughness = g->roughness };
    for (int k = 0; k < 3; k++) {
        v.base[k] = g->base_color[k];
        v.emission[k] = g->emissive[k] * g->emissive_strength;
    }
    return v;
}

/* glTF material gltf_index (its values v) as ptr's (docs/scenes.md). */
static PtrResult convert_material(Importer *im, int gltf_index, const GltfMaterial *g,
                                  const MaterialValues *v, PtrMaterial *m)
{
    if (!all_finite(g->base_color, 4) || !all_finite(v->base, 3) ||
        !all_finite(v->emission, 3) || !isfinite(g->ior) || !isfinite(v->roughness) ||
        !isfinite(v->metallic) || !isfinite(g->transmission) || !(g->ior > 0.0) ||
        v->emission[0] < 0 || v->emission[1] < 0 || v->emission[2] < 0)
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
    return PTR_OK;
}

static PtrResult add_material(Importer *im, const PtrMaterial *m, uint32_t *out)
{
    if (ptr_scene_add_material(im->scene, m, out, NULL) != PTR_OK)
        return ptr_error_set(im->err, PTR_ERR_NOMEM, "%s: out of memory", im->path);
    return PTR_OK;
}

static PtrResult map_material(Importer *im, int gltf_index, uint32_t *out)
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
        if (has_color_texture(&g) && !im->warned_texture) {
            im->warned_texture = 1;
            ptr_warn(im->warnings, "%s: textures are ignored without an image reader or "
                     "vertices to read them at (first seen on material '%s')", im->path,
                     label(g.name, "unnamed"));
        }
        const MaterialValues v = factor_values(&g);
        PtrResult res = convert_material(im, gltf_index, &g, &v, &m);
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

/* The scene material of value m, made once however many spheres have it:
 * a million spheres of a palette of a hundred colours make a hundred. */
static PtrResult made_material(Importer *im, const PtrMaterial *m, uint32_t *out)
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

/* What a sphere is made for, for messages: "node 3 ('Cloud')", with
 * ", instance 17" or ", point 5" after it. */
typedef struct Origin {
    size_t node_index;
    const char *node_name;
    const char *part;  /* "instance", "point" or NULL */
    size_t part_index;
} Origin;

static void origin_text(const Origin *o, char *out, size_t size)
{
    int n = snprintf(out, size, "node %zu ('%s')", o->node_index, o->node_name);
    if (o->part && n >= 0 && (size_t)n < size)
        snprintf(out + n, size - (size_t)n, ", %s %zu", o->part, o->part_index);
}

/* The largest of world's axis scales; *nonuniform set if they differ. */
static double axis_scale(const Mat4 *world, int *nonuniform)
{
    double scale[3] = { column_length(world, 0), column_length(world, 1),
                        column_length(world, 2) };
    /* Not fmin and fmax, library calls here: lengths are never NaN. */
    double smin = scale[0], smax = scale[0];
    for (int k = 1; k < 3; k++) {
        smin = scale[k] < smin ? scale[k] : smin;
        smax = scale[k] > smax ? scale[k] : smax;
    }
    if (smax - smin > 1e-6 * smax)
        *nonuniform = 1;
    return smax;
}

static void warn_nonuniform(Importer *im, const Origin *o, int *warned)
{
    if (*warned)
        return;
    *warned = 1;
    ptr_warn(im->warnings, "%s: node '%s' has a non-uniform scale; its spheres take the largest axis",
             im->path, o->node_name);
}

/* Whether a sphere cannot be rendered: its centre or radius in float. */
static int sphere_fault(const double centre[3], double radius)
{
    float r = (float)radius;
    return !(r > 0.0f) || !isfinite(r) || !all_finite(centre, 3);
}

/* "FILE: node 3 ('name'), instance 17 PROBLEM" (see Origin). */
static PtrResult part_error(Importer *im, const Origin *o, const char *problem)
{
    char where[160];
    origin_text(o, where, sizeof where);
    return ptr_error_set(im->err, PTR_ERR_SCENE_INVALID, "%s: %s %s", im->path, where, problem);
}

static const char *const sphere_fault_text =
    "gives a sphere with a non-finite centre or a radius that is not positive and finite";
static const char *const transform_fault_text =
    "has a non-finite transform, a zero rotation or a scale that is not positive";

/* Surface sphere k of a node under world, where the node has a radius or
 * the mesh's sphere k (sized by scale, world's largest axis scale). */
static void surface_sphere(const GltfNode *node, const SurfaceSpheres *surface, size_t k,
                           const Mat4 *world, double scale, double centre[3], double *radius)
{
    if (node->has_radius) {
        const double origin[3] = { 0, 0, 0 };
        mat4_point(world, origin, centre);
        *radius = node->radius;
        return;
    }
    mat4_point(world, &surface->spheres[4 * k], centre);
    *radius = surface->spheres[4 * k + 3] * scale;
}

/* What kinds of stored numbers an attribute accepts. */
typedef enum Components {
    FLOATS,              /* float only */
    FLOATS_OR_SIGNED,    /* float, normalized byte or short */
    FLOATS_OR_UNSIGNED,  /* float, normalized unsigned byte or short */
    QUANTIZED,           /* float, or any byte or short, normalized or not
                          * (KHR_mesh_quantization) */
} Components;

/* Checks accessor index as attribute `what` of o's node: its type (between
 * min_components and max_components numbers an element), its stored numbers,
 * and, unless *count is 0, that it has *count elements (else sets *count). The
 * accessor's bounds within its buffer were checked when the file loaded. */
static PtrResult attribute_accessor(Importer *im, const Origin *o, const char *what, int index,
                                    int min_components, int max_components, Components kinds,
                                    size_t *count, GltfAccessor *a)
{
    gltf_doc_accessor(im->doc, (size_t)index, a);
    const int t = a->component_type;
    int integer = t == GLTF_BYTE || t == GLTF_UNSIGNED_BYTE || t == GLTF_SHORT ||
                  t == GLTF_UNSIGNED_SHORT;
    int kind_ok = (t == GLTF_FLOAT && !a->normalized) || (kinds == QUANTIZED && integer) ||
                  (kinds == FLOATS_OR_SIGNED && a->normalized && (t == GLTF_BYTE || t == GLTF_SHORT)) ||
                  (kinds == FLOATS_OR_UNSIGNED && a->normalized &&
                   (t == GLTF_UNSIGNED_BYTE || t == GLTF_UNSIGNED_SHORT));
    const char *fault = a->sparse ? "is sparse, which ptr does not read"
                        : !a->data ? "has no buffer view"
                        : a->components < min_components || a->components > max_components
                            ? "has the wrong type"
                        : !kind_ok ? "has a component type its attribute does not allow"
                        : *count && a->count != *count ? "has a count that differs from the other attributes'"
                        : a->count == 0 ? "is empty"
                                        : NULL;
    if (fault) {
        char where[160];
        origin_text(&(Origin){ o->node_index, o->node_name, NULL, 0 }, where, sizeof where);
        return ptr_error_set(im->err, PTR_ERR_SCENE_INVALID, "%s: %s: %s accessor %d %s",
                             im->path, where, what, index, fault);
    }
    *count = a->count;
    return PTR_OK;
}

/* Element i of an accessor checked by attribute_accessor, each component
 * as gltf_component_value reads it. Missing components are 0. */
static void element(const GltfAccessor *a, size_t i, double out[4])
{
    const unsigned char *p = a->data + i * a->stride;
    if (a->component_type == GLTF_FLOAT) { /* the common case, without a switch a component */
        float f[4] = { 0, 0, 0, 0 };
        memcpy(f, p, (size_t)a->components * sizeof *f);
        for (int c = 0; c < 4; c++)
            out[c] = f[c];
        return;
    }
    for (int c = 0; c < 4; c++) {
        double raw = 0;
        if (c < a->components) {
            switch (a->component_type) {
            case GLTF_FLOAT: { float f; memcpy(&f, p + 4 * c, 4); raw = f; break; }
            case GLTF_UNSIGNED_BYTE: raw = p[c]; break;
            case GLTF_BYTE: raw = (signed char)p[c]; break;
            case GLTF_UNSIGNED_SHORT: { uint16_t u; memcpy(&u, p + 2 * c, 2); raw = u; break; }
            case GLTF_SHORT: { int16_t u; memcpy(&u, p + 2 * c, 2); raw = u; break; }
            }
        }
        out[c] = gltf_component_value(a->component_type, a->normalized, raw);
    }
}

/* A surface primitive's part of its mesh's vertices and triangles. */
typedef struct SurfacePart {
    GltfAccessor pos, idx; /* idx read where has_idx says */
    int has_idx, mode, primitive;
    size_t first_vertex, first_triangle, triangles;
} SurfacePart;

typedef struct SurfaceParts {
    SurfacePart *parts;
    size_t count;
} SurfaceParts;

/* The part holding vertex or triangle `at` (by_triangle), parts in order. */
static const SurfacePart *part_of(const SurfaceParts *s, size_t at, int by_triangle)
{
    size_t lo = 0, hi = s->count;
    while (hi - lo > 1) {
        const size_t mid = lo + (hi - lo) / 2;
        const SurfacePart *p = &s->parts[mid];
        if ((by_triangle ? p->first_triangle : p->first_vertex) <= at)
            lo = mid;
        else
            hi = mid;
    }
    return &s->parts[lo];
}

static size_t index_at(const GltfAccessor *a, size_t i)
{
    const unsigned char *p = a->data + i * a->stride;
    uint32_t u32;
    uint16_t u16;
    switch (a->component_type) {
    case GLTF_UNSIGNED_BYTE: return p[0];
    case GLTF_UNSIGNED_SHORT: memcpy(&u16, p, 2); return u16;
    default: memcpy(&u32, p, 4); return u32;
    }
}

/* Vertex j of a part's triangle list, strip or fan (as its mode says). */
static size_t part_vertex(const SurfacePart *p, size_t j)
{
    return p->first_vertex + (p->has_idx ? index_at(&p->idx, j) : j);
}

static void float_position(const unsigned char *at, double out[3])
{
    float f[3];
    memcpy(f, at, sizeof f);
    for (int k = 0; k < 3; k++)
        out[k] = f[k];
}

/* Vertex v of part p (from p's first), as element reads it. */
static void part_position(const SurfacePart *p, size_t v, double out[3])
{
    if (p->pos.component_type == GLTF_FLOAT) { /* the common case, read at once */
        float_position(p->pos.data + v * p->pos.stride, out);
        return;
    }
    double e[4];
    element(&p->pos, v, e);
    memcpy(out, e, 3 * sizeof *out);
}

/* Triangles j .. j + count - 1 of part p as mesh vertices. */
static void part_triangles(const SurfacePart *p, size_t j, size_t count, uint32_t (*out)[3])
{
    const uint32_t base = (uint32_t)p->first_vertex;
    if (p->mode == 4 && p->has_idx && p->idx.component_type == GLTF_UNSIGNED_INT &&
        p->idx.stride == 4) { /* the common case of a large mesh, read at once */
        const unsigned char *at = p->idx.data + 12 * j;
        for (size_t i = 0; i < count; i++, at += 12) {
            uint32_t tri[3];
            memcpy(tri, at, sizeof tri);
            for (int k = 0; k < 3; k++)
                out[i][k] = base + tri[k];
        }
        return;
    }
    for (size_t i = 0; i < count; i++, j++) {
        const size_t at[3] = { p->mode == 4 ? 3 * j : p->mode == 6 ? 0 : j,
                               p->mode == 4 ? 3 * j + 1 : j + 1,
                               p->mode == 4 ? 3 * j + 2 : j + 2 };
        for (int k = 0; k < 3; k++)
            out[i][k] = (uint32_t)part_vertex(p, at[k]);
    }
}

static void mesh_positions(const void *user, size_t first, size_t count, double (*out)[3])
{
    const SurfacePart *p = part_of(user, first, 0);
    for (size_t i = 0; i < count; p++) {
        const size_t v = first + i - p->first_vertex;
        const size_t run = p->pos.count - v < count - i ? p->pos.count - v : count - i;
        if (p->pos.component_type == GLTF_FLOAT) /* the common case, its type asked once */
            for (size_t k = 0; k < run; k++)
                float_position(p->pos.data + (v + k) * p->pos.stride, out[i + k]);
        else
            for (size_t k = 0; k < run; k++)
                part_position(p, v + k, out[i + k]);
        i += run;
    }
}

static void mesh_gather(const void *user, const uint32_t *vertices, size_t count,
                        double (*out)[3])
{
    const SurfacePart *p = part_of(user, vertices[0], 0);
    for (size_t i = 0; i < count; i++) {
        if (vertices[i] < p->first_vertex || vertices[i] - p->first_vertex >= p->pos.count)
            p = part_of(user, vertices[i], 0);
        part_position(p, vertices[i] - p->first_vertex, out[i]);
    }
}

static void mesh_triangles(const void *user, size_t first, size_t count, uint32_t (*out)[3])
{
    const SurfacePart *p = part_of(user, first, 1);
    for (size_t i = 0; i < count; p++) {
        const size_t j = first + i - p->first_triangle;
        const size_t run = p->triangles - j < count - i ? p->triangles - j : count - i;
        part_triangles(p, j, run, out + i);
        i += run;
    }
}

/* The step of a position accessor's storage (mesh_spheres.h). */
static double position_quantum(const GltfAccessor *a)
{
    if (a->component_type == GLTF_FLOAT)
        return 0.0;
    return a->normalized ? gltf_component_value(a->component_type, 1, 1.0) : 1.0;
}

/* Keeps in *failed the least slot that fails: the one a serial import
 * reports, whichever thread meets it first. */
static void note_failure(atomic_size_t *failed, size_t slot)
{
    size_t seen = atomic_load(failed);
    while (slot < seen && !atomic_compare_exchange_weak(failed, &seen, slot))
        ;
}

/* The indices of a primitive, checked on all cores for a large one: the
 * first past the primitive's vertices. */
typedef struct IndexCheck {
    const GltfAccessor *indices;
    size_t vertices;
    atomic_size_t first_past; /* SIZE_MAX: none */
} IndexCheck;

enum { PARALLEL_INDICES = 1 << 18 };

static void check_indices(void *arg, size_t from, size_t to)
{
    IndexCheck *c = arg;
    const GltfAccessor *a = c->indices;
    /* 32-bit indices, the common case of a large mesh: the largest of each
     * chunk first, the chunk searched only if it is past the vertices. */
    for (; a->component_type == GLTF_UNSIGNED_INT && a->stride == 4 && to - from >= 4096;
         from += 4096) {
        uint32_t chunk[4096], largest = 0;
        memcpy(chunk, a->data + 4 * from, sizeof chunk);
        for (size_t i = 0; i < 4096; i++)
            largest = chunk[i] > largest ? chunk[i] : largest;
        if (largest >= c->vertices)
            break;
    }
    for (size_t i = from; i < to; i++)
        if (index_at(a, i) >= c->vertices) {
            note_failure(&c->first_past, i);
            return;
        }
}

/* Primitive p of mesh as a surface part, checked: its positions, its
 * indices and that they are in range. Lines (and fewer than 3 corners) give
 * no triangles: part->triangles 0. part->first_vertex holds its vertex
 * count until find_surface places it. */
static PtrResult surface_part(Importer *im, const Origin *o, size_t mesh, size_t p,
                              const GltfPrimitive *prim, SurfacePart *part)
{
    char where[160];
    origin_text(o, where, sizeof where);
    if (prim->position < 0)
        return ptr_error_set(im->err, PTR_ERR_SCENE_INVALID,
                             "%s: %s: mesh %zu primitive %zu has no POSITION", im->path, where,
                             mesh, p);
    size_t vertices = 0;
    PtrResult res = attribute_accessor(im, o, "POSITION", prim->position, 3, 3, QUANTIZED,
                                       &vertices, &part->pos);
    if (res != PTR_OK)
        return res;
    part->mode = prim->mode;
    part->primitive = (int)p;
    part->has_idx = prim->indices >= 0;
    size_t n = vertices;
    if (part->has_idx) {
        gltf_doc_accessor(im->doc, (size_t)prim->indices, &part->idx);
        const GltfAccessor *a = &part->idx;
        if (!a->data || a->sparse || a->components != 1 || a->normalized ||
            !(a->component_type == GLTF_UNSIGNED_BYTE || a->component_type == GLTF_UNSIGNED_SHORT ||
              a->component_type == GLTF_UNSIGNED_INT))
            return ptr_error_set(im->err, PTR_ERR_SCENE_INVALID,
                                 "%s: %s: mesh %zu primitive %zu has indices that are not "
                                 "unsigned integers in a buffer", im->path, where, mesh, p);
        n = a->count;
        IndexCheck check = { .indices = a, .vertices = vertices };
        atomic_init(&check.first_past, SIZE_MAX);
        ptr_parallel_ranges(n >= PARALLEL_INDICES ? ptr_online_cpus() : 1, 0, n, check_indices,
                            &check);
        const size_t past = atomic_load(&check.first_past);
        if (past != SIZE_MAX)
            return ptr_error_set(im->err, PTR_ERR_SCENE_INVALID,
                                 "%s: %s: mesh %zu primitive %zu has index %zu past its "
                                 "%zu vertices", im->path, where, mesh, p, index_at(a, past),
                                 vertices);
    }
    part->triangles = prim->mode == 4 ? n / 3 : (prim->mode == 5 || prim->mode == 6) && n >= 3
                                                    ? n - 2 : 0;
    part->first_vertex = vertices;
    return PTR_OK;
}

/* A mesh's spheres from its bounds alone: one, unchecked, where its
 * vertices are not there to read: compressed by Draco, which ptr does not
 * decode, or a POSITION accessor with bounds but no buffer view (files
 * written by hand to place a sphere). */
static PtrResult bounds_sphere(Importer *im, const Origin *o, size_t mesh_index,
                               const GltfMesh *mesh, SurfaceSpheres *out)
{
    if (!mesh->has_bounds)
        return ptr_error_set(im->err, PTR_ERR_SCENE_INVALID,
                             "%s: node %zu ('%s'): mesh %zu has no POSITION min/max bounds",
                             im->path, o->node_index, o->node_name, mesh_index);
    double extent = 0.0;
    for (int k = 0; k < 3; k++) {
        out->spheres[k] = 0.5 * (mesh->min[k] + mesh->max[k]);
        extent = fmax(extent, mesh->max[k] - mesh->min[k]);
    }
    out->spheres[3] = 0.5 * extent;
    for (size_t p = 0; p < mesh->primitive_count; p++) { /* the first surface primitive's */
        GltfPrimitive prim;
        gltf_doc_primitive(im->doc, mesh_index, p, &prim);
        if (!prim.points) {
            out->primitives[0] = (int)p;
            break;
        }
    }
    out->count = 1;
    return PTR_OK;
}

/* A primitive's material, or glTF's stand-in for none: ptr's default grey
 * (docs/scenes.md). */
static void primitive_material(const Importer *im, const GltfPrimitive *prim, GltfMaterial *g)
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

/* Whether a primitive's spheres take their colours from its vertices: its
 * material's textures (where the import reads them) or its COLOR_0. */
static int colored_by_vertices(const Importer *im, const GltfPrimitive *prim)
{
    GltfMaterial g;
    primitive_material(im, prim, &g);
    return prim->color >= 0 || (im->textures && has_color_texture(&g));
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
        res = attribute_accessor(im, o, name, index, 2, 2, QUANTIZED, &count, &vc->uv[r]);
    }
    vc->has_color = prim->color >= 0;
    if (res == PTR_OK && vc->has_color)
        res = attribute_accessor(im, o, "COLOR_0", prim->color, 3, 4, FLOATS_OR_UNSIGNED, &count,
                                 &vc->color);
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
        element(&vc->color, v, e);
        for (int k = 0; k < 3; k++)
            out[k] = (float)e[k];
    }
    for (int r = 0; r < 3; r++) {
        if (!vc->refs[r])
            continue;
        float texel[4];
        element(&vc->uv[r], v, e);
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
    if (!colored_by_vertices(im, &prim))
        return PTR_OK;
    primitive_material(im, &prim, &g);
    VertexColors vc;
    PtrResult res = vertex_colors(im, o, mesh_index, part, &prim, &g, &vc);
    for (size_t v = 0; v < part->pos.count && res == PTR_OK; v++) {
        const uint32_t c = labels[part->first_vertex + v];
        if (c == UINT32_MAX || !found[c].is_sphere ||
            part_of(s, found[c].first_triangle, 1) != part)
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
                       (size_t)part_of(s, found[c].first_triangle, 1)->primitive, &prim);
    primitive_material(im, &prim, &g);
    MaterialValues v = factor_values(&g);
    const double n = (double)sum->vertices;
    for (int k = 0; k < 3; k++) {
        v.base[k] *= sum->sum[k] / n;
        v.emission[k] *= sum->sum[3 + k] / n;
    }
    v.metallic *= sum->sum[6] / n;
    v.roughness *= sum->sum[7] / n;
    im->varying += sum->varies;
    PtrMaterial m;
    PtrResult res = convert_material(im, prim.material, &g, &v, &m);
    return res == PTR_OK ? made_material(im, &m, out) : res;
}

/* Each sphere's own material (out->materials) where its vertices colour it:
 * labels give each vertex's component among found. */
static PtrResult surface_colors(Importer *im, const Origin *o, size_t mesh_index,
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

/* The components of a mesh's surface primitives, as o first meets them. */
static PtrResult find_surface(Importer *im, const Origin *o, size_t mesh_index,
                              const GltfMesh *mesh, SurfaceSpheres *out)
{
    SurfaceParts s = { malloc((mesh->primitive_count ? mesh->primitive_count : 1) *
                              sizeof *s.parts), 0 };
    if (!s.parts)
        return ptr_error_set(im->err, PTR_ERR_NOMEM, "%s: out of memory", im->path);
    PtrResult res = PTR_OK;
    size_t vertices = 0, triangles = 0, lines = 0;
    for (size_t p = 0; p < mesh->primitive_count && res == PTR_OK; p++) {
        GltfPrimitive prim;
        gltf_doc_primitive(im->doc, mesh_index, p, &prim);
        if (prim.points)
            continue;
        SurfacePart *part = &s.parts[s.count];
        res = surface_part(im, o, mesh_index, p, &prim, part);
        if (res != PTR_OK || !part->triangles) {
            lines += res == PTR_OK;
            continue;
        }
        const size_t count = part->first_vertex;
        part->first_vertex = vertices;
        part->first_triangle = triangles;
        vertices += count;
        triangles += part->triangles;
        s.count++;
    }
    if (res == PTR_OK && vertices >= UINT32_MAX)
        res = ptr_error_set(im->err, PTR_ERR_SCENE_INVALID,
                            "%s: mesh %zu has more vertices than ptr reads (%zu)", im->path,
                            mesh_index, vertices);
    PtrMeshSphere *found = NULL;
    uint32_t *labels = NULL;
    size_t components = 0;
    int colored = 0;
    for (size_t p = 0; p < s.count; p++) {
        GltfPrimitive prim;
        gltf_doc_primitive(im->doc, mesh_index, (size_t)s.parts[p].primitive, &prim);
        colored |= colored_by_vertices(im, &prim);
    }
    const PtrMeshSource source = {
        .vertex_count = vertices, .triangle_count = triangles, .positions = mesh_positions,
        .gather = mesh_gather, .triangles = mesh_triangles, .user = &s,
    };
    PtrMeshSource quantised = source;
    for (size_t p = 0; p < s.count; p++)
        quantised.quantum = fmax(quantised.quantum, position_quantum(&s.parts[p].pos));
    if (res == PTR_OK)
        res = ptr_mesh_spheres(&quantised, im->path, &found, &components,
                               colored ? &labels : NULL, im->err);
    if (res == PTR_OK) {
        out->spheres = malloc((components ? components : 1) * 4 * sizeof *out->spheres);
        out->primitives = malloc((components ? components : 1) * sizeof *out->primitives);
        if (!out->spheres || !out->primitives)
            res = ptr_error_set(im->err, PTR_ERR_NOMEM, "%s: out of memory", im->path);
    }
    out->skipped = lines;
    for (size_t c = 0; res == PTR_OK && c < components; c++) {
        if (!found[c].is_sphere) {
            out->skipped++;
            continue;
        }
        memcpy(&out->spheres[4 * out->count], found[c].centre, sizeof found[c].centre);
        out->spheres[4 * out->count + 3] = found[c].radius;
        out->primitives[out->count++] = part_of(&s, found[c].first_triangle, 1)->primitive;
    }
    if (res == PTR_OK && colored)
        res = surface_colors(im, o, mesh_index, &s, found, components, labels, out);
    free(labels);
    free(found);
    free(s.parts);
    return res;
}

/* What the spheres of primitive p of a mesh depend on: whether it is POINTS,
 * else its accessors and mode, and where its vertices colour the spheres,
 * its material, COLOR_0 and first two TEXCOORDs. */
enum { SURFACE_NUMBERS = 9 };
static void surface_numbers(const Importer *im, size_t mesh_index, size_t p,
                            int64_t out[SURFACE_NUMBERS])
{
    GltfPrimitive prim;
    gltf_doc_primitive(im->doc, mesh_index, p, &prim);
    memset(out, 0, SURFACE_NUMBERS * sizeof *out);
    out[0] = prim.points;
    if (prim.points)
        return;
    out[1] = prim.position;
    out[2] = prim.indices;
    out[3] = prim.mode;
    out[4] = prim.draco;
    if (!colored_by_vertices(im, &prim))
        return;
    out[5] = prim.material;
    out[6] = prim.color;
    out[7] = gltf_doc_primitive_attribute(im->doc, mesh_index, p, "TEXCOORD_0");
    out[8] = gltf_doc_primitive_attribute(im->doc, mesh_index, p, "TEXCOORD_1");
}

/* Whether meshes a and b have the same surface: the same primitives other
 * than POINTS (see surface_numbers), in the same places. */
static int same_surface(const Importer *im, size_t a, size_t b)
{
    GltfMesh ma, mb;
    gltf_doc_mesh(im->doc, a, &ma);
    gltf_doc_mesh(im->doc, b, &mb);
    for (size_t p = 0; p < ma.primitive_count && ma.primitive_count == mb.primitive_count; p++) {
        int64_t na[SURFACE_NUMBERS], nb[SURFACE_NUMBERS];
        surface_numbers(im, a, p, na);
        surface_numbers(im, b, p, nb);
        if (memcmp(na, nb, sizeof na))
            return 0;
    }
    return ma.primitive_count == mb.primitive_count;
}

/* A hash of what same_surface compares. */
static uint64_t surface_key(const Importer *im, size_t mesh_index)
{
    GltfMesh mesh;
    gltf_doc_mesh(im->doc, mesh_index, &mesh);
    uint64_t h = 0xcbf29ce484222325u; /* FNV-1a over the numbers */
    for (size_t p = 0; p < mesh.primitive_count; p++) {
        int64_t part[SURFACE_NUMBERS];
        surface_numbers(im, mesh_index, p, part);
        for (int k = 0; k < SURFACE_NUMBERS; k++)
            h = (h ^ (uint64_t)part[k]) * 0x100000001b3u;
    }
    return h;
}

/* The earlier mesh of the same surface as mesh_index, if one was found,
 * else mesh_index, entered in the table. */
static size_t surface_owner(Importer *im, size_t mesh_index)
{
    const size_t mask = im->surface_slots - 1;
    for (size_t slot = surface_key(im, mesh_index) & mask;; slot = (slot + 1) & mask) {
        const size_t other = im->surface_table[slot];
        if (other == SIZE_MAX) {
            im->surface_table[slot] = mesh_index;
            return mesh_index;
        }
        if (same_surface(im, other, mesh_index))
            return other;
    }
}

/* The spheres of mesh_index's surface, found at the first node using it
 * (o); the node's extras.radius aside, which needs none. */
static PtrResult surface_spheres(Importer *im, const Origin *o, size_t mesh_index,
                                 const SurfaceSpheres **out)
{
    SurfaceSpheres *s = &im->surfaces[mesh_index];
    if (!s->same)
        s->same = &im->surfaces[surface_owner(im, mesh_index)];
    *out = s->same;
    if (s->same != s || s->found)
        return PTR_OK;
    s->found = 1;
    GltfMesh mesh;
    gltf_doc_mesh(im->doc, mesh_index, &mesh);
    if (!mesh.has_surface)
        return PTR_OK;
    int unread = 0;
    for (size_t p = 0; p < mesh.primitive_count; p++) {
        GltfPrimitive prim;
        GltfAccessor a = { .data = NULL };
        gltf_doc_primitive(im->doc, mesh_index, p, &prim);
        if (!prim.points && prim.position >= 0)
            gltf_doc_accessor(im->doc, (size_t)prim.position, &a);
        unread |= !prim.points && (prim.draco || (prim.position >= 0 && !a.data));
    }
    if (!unread)
        return find_surface(im, o, mesh_index, &mesh, s);
    s->spheres = malloc(4 * sizeof *s->spheres);
    s->primitives = malloc(sizeof *s->primitives);
    if (!s->spheres || !s->primitives)
        return ptr_error_set(im->err, PTR_ERR_NOMEM, "%s: out of memory", im->path);
    return bounds_sphere(im, o, mesh_index, &mesh, s);
}

/* Notes a node's mesh parts that are not spheres for the file's warning. */
static void note_skipped(Importer *im, const Origin *o, const GltfMesh *mesh, size_t parts)
{
    if (!parts)
        return;
    im->skipped += parts;
    char name[sizeof im->skipped_names];
    const size_t used = strlen(im->skipped_names);
    const int n = snprintf(name, sizeof name, "%snode '%s' (mesh '%s')", used ? ", " : "",
                           o->node_name, label(mesh->name, "unnamed"));
    if (n < 0 || used + (size_t)n >= sizeof im->skipped_names)
        im->skipped_more = 1;
    else
        memcpy(im->skipped_names + used, name, (size_t)n + 1);
}

/* Checks the accessor of the attribute --color-by names (index from
 * gltf_doc_*_attribute: -2 if it names no accessor) as o's `what`. */
static PtrResult value_accessor(Importer *im, const Origin *o, const char *what, int index,
                                size_t *count, GltfAccessor *a)
{
    if (index == -2) {
        char where[160];
        origin_text(o, where, sizeof where);
        return ptr_error_set(im->err, PTR_ERR_SCENE_INVALID,
                             "%s: %s: %s attribute '%s' refers to an accessor that does not "
                             "exist", im->path, where, what, im->value_name);
    }
    return attribute_accessor(im, o, im->value_name, index, 1, 4, QUANTIZED, count, a);
}

/* Element i of a value accessor: the number, or the length of a vector
 * (docs/scenes.md). Returns 0 unless it is finite. */
static int element_value(const GltfAccessor *a, size_t i, double *value)
{
    double v[4], sum = 0;
    element(a, i, v);
    for (int c = 0; c < a->components; c++)
        sum += v[c] * v[c];
    *value = a->components == 1 ? v[0] : sqrt(sum);
    return isfinite(*value);
}

/* T * R * S of instance i, from the attributes present. */
static int instance_local(const GltfAccessor *t, const GltfAccessor *r, const GltfAccessor *s,
                          size_t i, Mat4 *out)
{
    double translation[3] = { 0, 0, 0 }, rotation[4] = { 0, 0, 0, 1 }, scale[3] = { 1, 1, 1 };
    double v[4];
    if (t) {
        element(t, i, v);
        memcpy(translation, v, sizeof translation);
    }
    if (r) {
        element(r, i, v);
        double length = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + v[3] * v[3]);
        if (!(length > 0) || !isfinite(length))
            return 0;
        for (int k = 0; k < 4; k++)
            rotation[k] = v[k] / length; /* quantized rotations are not quite unit */
    }
    if (s) {
        element(s, i, v);
        for (int k = 0; k < 3; k++)
            if (!(v[k] > 0) || !isfinite(v[k]))
                return 0;
        memcpy(scale, v, sizeof scale);
    }
    *out = trs_matrix(translation, rotation, scale);
    return all_finite(out->m, 16);
}

/* A point's colour: its COLOR_0 c (NULL: none) times the colour of the
 * instance it is part of (NULL: none); one of them is given. */
static void point_color(const double *c, const double *instance, double rgb[3])
{
    for (int k = 0; k < 3; k++)
        rgb[k] = c ? c[k] * (instance ? instance[k] : 1.0) : instance[k];
}

/* A POINTS primitive, checked: each point a sphere. */
typedef struct PointSet {
    GltfAccessor pos, rad, col, val; /* rad, col, val read only where has_ says */
    int has_rad, has_col, has_val;   /* val: the --color-by attribute */
    double radius;                   /* without rad, the node's extras.radius */
    uint32_t material;
    size_t count;
} PointSet;

/* A node's spheres: for each of its instances (one for a node without
 * EXT_mesh_gpu_instancing), its mesh's surface sphere if it has a surface,
 * then each POINTS primitive's points, per_instance spheres in all, placed
 * in this order from the builder's sphere first. An instance is `slots`
 * slots, one a sphere (one if it has none: its attributes are checked all
 * the same), and slot n is converted the same on any thread, so the spheres
 * do not depend on how many convert them. */
typedef struct NodeRun {
    PtrSceneBuilder *builder;
    const GltfNode *node;
    const GltfMesh *mesh;
    const SurfaceSpheres *surface;
    size_t surface_count;        /* surface spheres an instance */
    uint32_t *surface_materials; /* theirs */
    const Mat4 *world;
    int instanced;
    GltfAccessor t, r, s, c, v; /* the instances' attributes, read where has_ says */
    int has_t, has_r, has_s, has_c, has_v;
    PointSet *sets;
    size_t set_count;
    int scaled; /* whether any sphere takes world's largest axis scale */
    size_t instances, per_instance, slots, first;
    atomic_size_t failed;  /* the least slot that fails; SIZE_MAX: none */
    atomic_int nonuniform; /* whether a scaled sphere's axis scales differ */
} NodeRun;

/* What the spheres of an instance share. */
typedef struct Instance {
    Mat4 world;
    double color[4], value;
    int has_color, has_value;
    double scale; /* world's largest axis scale */
    int uneven;   /* whether its axis scales differ */
} Instance;

/* Why a slot gives no sphere. */
typedef enum Fault { NO_FAULT, TRANSFORM_FAULT, VALUE_FAULT, SPHERE_FAULT } Fault;

/* Instance i of the run, or why it gives no spheres. */
static Fault instance_at(const NodeRun *run, size_t i, Instance *out)
{
    out->world = *run->world;
    if (run->instanced) {
        Mat4 local;
        if (!instance_local(run->has_t ? &run->t : NULL, run->has_r ? &run->r : NULL,
                            run->has_s ? &run->s : NULL, i, &local))
            return TRANSFORM_FAULT;
        out->world = mat4_mul(run->world, &local);
    }
    out->has_color = run->has_c;
    if (run->has_c)
        element(&run->c, i, out->color);
    out->has_value = run->has_v;
    if (run->has_v && !element_value(&run->v, i, &out->value))
        return VALUE_FAULT;
    out->uneven = 0;
    out->scale = axis_scale(&out->world, &out->uneven);
    return NO_FAULT;
}

/* The set that sphere k of an instance (k past its surface sphere) belongs
 * to, and in *point which of its points it is. */
static size_t set_of(const NodeRun *run, size_t k, size_t *point)
{
    size_t set = 0, j = k - run->surface_count;
    while (set < run->set_count && j >= run->sets[set].count)
        j -= run->sets[set++].count;
    *point = j;
    return set;
}

/* Point j of ps in instance in as the builder's sphere n, or why it gives
 * none. */
static Fault point_sphere(const NodeRun *run, const Instance *in, const PointSet *ps, size_t j,
                          size_t n)
{
    double p[4], r[4], c[4], centre[3], rgb[3], value = in->has_value ? in->value : 0.0;
    element(&ps->pos, j, p);
    mat4_point(&in->world, p, centre);
    if (ps->has_rad)
        element(&ps->rad, j, r);
    else
        r[0] = ps->radius;
    if (ps->has_val && !element_value(&ps->val, j, &value))
        return VALUE_FAULT;
    const double radius = r[0] * in->scale;
    if (sphere_fault(centre, radius))
        return SPHERE_FAULT;
    if (ps->has_col)
        element(&ps->col, j, c);
    if (ps->has_col || in->has_color)
        point_color(ps->has_col ? c : NULL, in->has_color ? in->color : NULL, rgb);
    ptr_builder_fill_sphere(run->builder, n, centre, radius, ps->material,
                            ps->has_col || in->has_color ? rgb : NULL);
    if (ps->has_val || in->has_value)
        ptr_builder_fill_value(run->builder, n, value);
    return NO_FAULT;
}

/* Slots k .. end - 1 of instance i into the builder; on a fault, *at is
 * the slot. */
static Fault instance_spheres(const NodeRun *run, size_t i, const Instance *in, size_t k,
                              size_t end, size_t *at)
{
    size_t n = run->first + i * run->per_instance + k;
    for (; k < end && k < run->surface_count; k++, n++) {
        double centre[3], radius;
        surface_sphere(run->node, run->surface, k, &in->world, in->scale, centre, &radius);
        *at = k;
        if (sphere_fault(centre, radius))
            return SPHERE_FAULT;
        ptr_builder_fill_sphere(run->builder, n, centre, radius, run->surface_materials[k],
                                in->has_color ? in->color : NULL);
        if (in->has_value)
            ptr_builder_fill_value(run->builder, n, in->value);
    }
    if (k >= end)
        return NO_FAULT;
    size_t j;
    for (size_t set = set_of(run, k, &j); k < end && set < run->set_count; k++, n++) {
        *at = k;
        const Fault fault = point_sphere(run, in, &run->sets[set], j, n);
        if (fault != NO_FAULT)
            return fault;
        if (++j == run->sets[set].count)
            set++, j = 0;
    }
    return NO_FAULT;
}

/* Slots begin .. end - 1 of the run (see NodeRun). */
static void convert_slots(void *arg, size_t begin, size_t end)
{
    NodeRun *run = arg;
    int nonuniform = 0;
    for (size_t slot = begin; slot < end;) {
        const size_t i = slot / run->slots, k = slot % run->slots;
        const size_t stop = end - slot < run->slots - k ? k + (end - slot) : run->slots;
        Instance in;
        size_t at = 0;
        if (instance_at(run, i, &in) != NO_FAULT ||
            instance_spheres(run, i, &in, k, stop, &at) != NO_FAULT) {
            note_failure(&run->failed, i * run->slots + at);
            break;
        }
        nonuniform |= in.uneven;
        slot += stop - k;
    }
    if (nonuniform && run->scaled)
        atomic_store(&run->nonuniform, 1);
}

/* A node of this many slots or more is converted on all cores, and every
 * node PARALLEL_BLOCK slots at a time, the file's pages read given back
 * after each block. */
enum { PARALLEL_PARTS = 1 << 15, PARALLEL_BLOCK = 1 << 20 };

/* Gives back the file's pages read for slots begin .. end - 1 (see
 * gltf_doc_release): the instances' attributes, or the points' where no
 * other instance reads them again. */
static void release_slots(const Importer *im, const NodeRun *run, size_t begin, size_t end)
{
    if (run->instanced) {
        const GltfAccessor *read[] = { run->has_t ? &run->t : NULL, run->has_r ? &run->r : NULL,
                                       run->has_s ? &run->s : NULL, run->has_c ? &run->c : NULL,
                                       run->has_v ? &run->v : NULL };
        for (size_t a = 0; a < sizeof read / sizeof read[0]; a++)
            if (read[a])
                gltf_doc_release(im->doc, read[a], begin / run->slots, end / run->slots);
        return;
    }
    size_t from = run->surface_count; /* the slot of the set's point 0 */
    for (size_t set = 0; set < run->set_count; from += run->sets[set++].count) {
        const PointSet *ps = &run->sets[set];
        if (end <= from || begin >= from + ps->count)
            continue;
        const size_t lo = begin > from ? begin - from : 0;
        const size_t hi = end - from < ps->count ? end - from : ps->count;
        const GltfAccessor *read[] = { &ps->pos, ps->has_rad ? &ps->rad : NULL,
                                       ps->has_col ? &ps->col : NULL,
                                       ps->has_val ? &ps->val : NULL };
        for (size_t a = 0; a < sizeof read / sizeof read[0]; a++)
            if (read[a])
                gltf_doc_release(im->doc, read[a], lo, hi);
    }
}

static PtrResult value_error(Importer *im, const Origin *o)
{
    char where[160];
    origin_text(o, where, sizeof where);
    return ptr_error_set(im->err, PTR_ERR_SCENE_INVALID, "%s: %s: attribute '%s' is not finite",
                         im->path, where, im->value_name);
}

/* The error of the run's slot that failed, as a serial import meets it
 * (instance: the node's origin, with "instance" if it has instances). */
static PtrResult slot_error(Importer *im, const NodeRun *run, const Origin *instance,
                            size_t slot)
{
    const size_t i = slot / run->slots, k = slot % run->slots;
    Origin o = *instance;
    o.part_index = i;
    Instance in;
    Fault fault = instance_at(run, i, &in);
    if (fault == TRANSFORM_FAULT)
        return part_error(im, &o, transform_fault_text);
    if (fault == VALUE_FAULT)
        return value_error(im, &o);
    size_t at = k;
    fault = instance_spheres(run, i, &in, k, k + 1, &at);
    if (at < run->surface_count)
        return part_error(im, &o, sphere_fault_text);
    o.part = "point";
    set_of(run, at, &o.part_index);
    return fault == SPHERE_FAULT ? part_error(im, &o, sphere_fault_text) : value_error(im, &o);
}

/* The attributes of an EXT_mesh_gpu_instancing node's instances, checked,
 * and their count. */
static PtrResult instance_attributes(Importer *im, const Origin *o, NodeRun *run)
{
    const GltfInstancing *in = &run->node->instances;
    if (in->translation < 0 && in->rotation < 0 && in->scale < 0)
        return ptr_error_set(im->err, PTR_ERR_SCENE_INVALID,
                             "%s: node %zu ('%s') has EXT_mesh_gpu_instancing without "
                             "TRANSLATION, ROTATION or SCALE", im->path, o->node_index,
                             o->node_name);
    run->has_t = in->translation >= 0;
    run->has_r = in->rotation >= 0;
    run->has_s = in->scale >= 0;
    run->has_c = in->color >= 0;
    size_t count = 0;
    PtrResult res = PTR_OK;
    if (run->has_t)
        res = attribute_accessor(im, o, "TRANSLATION", in->translation, 3, 3, QUANTIZED, &count,
                                 &run->t);
    if (res == PTR_OK && run->has_r)
        res = attribute_accessor(im, o, "ROTATION", in->rotation, 4, 4, FLOATS_OR_SIGNED, &count,
                                 &run->r);
    if (res == PTR_OK && run->has_s)
        res = attribute_accessor(im, o, "SCALE", in->scale, 3, 3, QUANTIZED, &count, &run->s);
    if (res == PTR_OK && run->has_c)
        res = attribute_accessor(im, o, "_COLOR_0", in->color, 3, 4, FLOATS_OR_UNSIGNED, &count,
                                 &run->c);
    const int value_index =
        im->value_name ? gltf_doc_instance_attribute(im->doc, o->node_index, im->value_name) : -1;
    run->has_v = value_index != -1;
    if (res == PTR_OK && run->has_v)
        res = value_accessor(im, o, "instance", value_index, &count, &run->v);
    run->instances = count;
    return res;
}

/* A POINTS primitive of the run's mesh, checked, its material mapped, as
 * the node's first instance (o, first) meets it; value_index: its --color-by
 * attribute, -1 if none. */
static PtrResult point_set(Importer *im, const Origin *o, const NodeRun *run,
                           const GltfPrimitive *prim, int value_index, const Instance *first,
                           int *warned, PointSet *ps)
{
    if (prim->radius < 0 && !run->node->has_radius)
        return ptr_error_set(im->err, PTR_ERR_SCENE_INVALID,
                             "%s: node %zu ('%s') has POINTS without a _RADIUS attribute or an "
                             "extras.radius", im->path, o->node_index, o->node_name);
    if (prim->position < 0)
        return ptr_error_set(im->err, PTR_ERR_SCENE_INVALID,
                             "%s: node %zu ('%s') has POINTS without POSITION", im->path,
                             o->node_index, o->node_name);
    if (prim->draco)
        return ptr_error_set(im->err, PTR_ERR_SCENE_INVALID,
                             "%s: node %zu ('%s') has POINTS compressed by "
                             "KHR_draco_mesh_compression, of which ptr reads only the bounds of "
                             "meshes", im->path, o->node_index, o->node_name);
    ps->has_rad = prim->radius >= 0;
    ps->has_col = prim->color >= 0;
    ps->has_val = value_index != -1;
    ps->radius = run->node->radius;
    ps->count = 0;
    PtrResult res = attribute_accessor(im, o, "POSITION", prim->position, 3, 3, QUANTIZED,
                                       &ps->count, &ps->pos);
    if (res == PTR_OK && ps->has_rad)
        res = attribute_accessor(im, o, "_RADIUS", prim->radius, 1, 1, FLOATS, &ps->count,
                                 &ps->rad);
    if (res == PTR_OK && ps->has_col)
        res = attribute_accessor(im, o, "COLOR_0", prim->color, 3, 4, FLOATS_OR_UNSIGNED,
                                 &ps->count, &ps->col);
    if (res == PTR_OK && ps->has_val)
        res = value_accessor(im, o, "point", value_index, &ps->count, &ps->val);
    if (res == PTR_OK)
        res = map_material(im, prim->material, &ps->material);
    if (res == PTR_OK && first->uneven)
        warn_nonuniform(im, o, warned);
    return res;
}

/* The run's mesh checked, its materials mapped and its point sets made,
 * with the warnings in the order a serial import gives them at the node's
 * first instance (o, first). */
static PtrResult run_mesh(Importer *im, const Origin *o, NodeRun *run, const Instance *first,
                          int *warned)
{
    const GltfNode *node = run->node;
    const GltfMesh *mesh = run->mesh;
    PtrResult res = PTR_OK;
    if (run->surface_count && !node->has_radius && first->uneven)
        warn_nonuniform(im, o, warned);
    int *materials = malloc((mesh->primitive_count ? mesh->primitive_count : 1) *
                            sizeof *materials); /* each primitive's */
    if (!materials)
        return ptr_error_set(im->err, PTR_ERR_NOMEM, "%s: out of memory", im->path);
    for (size_t p = 0; p < mesh->primitive_count; p++) {
        GltfPrimitive prim;
        gltf_doc_primitive(im->doc, (size_t)node->mesh, p, &prim);
        materials[p] = prim.material;
    }
    const uint32_t *own = node->has_radius ? NULL : run->surface->materials;
    for (size_t k = 0; k < run->surface_count && res == PTR_OK; k++) {
        if (own && own[k] != UINT32_MAX)
            run->surface_materials[k] = own[k];
        else
            res = map_material(im, node->has_radius ? mesh->material
                                                    : materials[run->surface->primitives[k]],
                               &run->surface_materials[k]);
    }
    free(materials);
    for (size_t p = 0; p < mesh->primitive_count && res == PTR_OK; p++) {
        GltfPrimitive prim;
        gltf_doc_primitive(im->doc, (size_t)node->mesh, p, &prim);
        if (!prim.points)
            continue;
        const int value_index = im->value_name ? gltf_doc_primitive_attribute(
                                                     im->doc, (size_t)node->mesh, p,
                                                     im->value_name)
                                               : -1;
        res = point_set(im, o, run, &prim, value_index, first, warned,
                        &run->sets[run->set_count++]);
    }
    return res;
}

/* Room in the builder for the run's spheres, with colours and values where
 * any of them has one. */
static PtrResult start_run(Importer *im, NodeRun *run)
{
    const int surface = run->surface_count > 0;
    int colored_all = run->has_c || !surface, colored_any = run->has_c, valued = run->has_v;
    run->per_instance = run->surface_count;
    for (size_t set = 0; set < run->set_count; set++) {
        const PointSet *ps = &run->sets[set];
        run->per_instance += ps->count;
        colored_all = colored_all && (run->has_c || ps->has_col);
        colored_any = colored_any || ps->has_col;
        valued = valued || ps->has_val;
    }
    run->slots = run->per_instance ? run->per_instance : 1;
    run->scaled = run->set_count > 0 || (surface && !run->node->has_radius);
    const size_t spheres = run->instances * run->per_instance;
    colored_any = colored_any && spheres > 0;
    colored_all = colored_all && colored_any;
    valued = valued && spheres > 0;
    /* Where only some spheres have their own colour, the others have none,
     * which the builder gives those it adds once it keeps colours. */
    if (((colored_any && !colored_all) || valued) &&
        ptr_builder_keep_attributes(run->builder, colored_any && !colored_all, valued, NULL) !=
            PTR_OK)
        return ptr_error_set(im->err, PTR_ERR_NOMEM, "%s: out of memory", im->path);
    if (ptr_builder_add_spheres(run->builder, spheres, colored_all, &run->first, NULL) != PTR_OK)
        return ptr_error_set(im->err, PTR_ERR_NOMEM, "%s: out of memory", im->path);
    return PTR_OK;
}

/* Converts the run's slots, on all cores where there are PARALLEL_PARTS or
 * more, a block at a time, and stops after a block where a slot failed. */
static void convert_run(const Importer *im, NodeRun *run)
{
    const size_t slots = run->instances * run->slots;
    const int threads = slots >= PARALLEL_PARTS ? ptr_online_cpus() : 1;
    for (size_t begin = 0; begin < slots && atomic_load(&run->failed) == SIZE_MAX;
         begin += PARALLEL_BLOCK) {
        const size_t end = slots - begin > PARALLEL_BLOCK ? begin + PARALLEL_BLOCK : slots;
        ptr_parallel_ranges(threads, begin, end, convert_slots, run);
        release_slots(im, run, begin, end);
    }
}

/* The node's spheres (see NodeRun): what they share checked first, as a
 * serial import meets it at the first instance. */
static PtrResult add_node_spheres(Importer *im, size_t node_index, const GltfNode *node,
                                  const Mat4 *world)
{
    GltfMesh mesh;
    gltf_doc_mesh(im->doc, (size_t)node->mesh, &mesh);
    const Origin o = { node_index, label(node->name, "unnamed"), NULL, 0 };
    const Origin instance = { node_index, o.node_name, node->instanced ? "instance" : NULL, 0 };
    NodeRun run = { .builder = &im->builder, .node = node, .mesh = &mesh, .world = world,
                    .instanced = node->instanced, .instances = 1, .slots = 1 };
    atomic_init(&run.failed, SIZE_MAX);
    atomic_init(&run.nonuniform, 0);
    PtrResult res = surface_spheres(im, &o, (size_t)node->mesh, &run.surface);
    if (res != PTR_OK)
        return res;
    run.surface_count = node->has_radius ? (size_t)mesh.has_surface : run.surface->count;
    run.sets = malloc((mesh.point_primitives ? mesh.point_primitives : 1) * sizeof *run.sets);
    run.surface_materials = malloc((run.surface_count ? run.surface_count : 1) *
                                   sizeof *run.surface_materials);
    if (!run.sets || !run.surface_materials)
        res = ptr_error_set(im->err, PTR_ERR_NOMEM, "%s: out of memory", im->path);
    if (res == PTR_OK && node->instanced)
        res = instance_attributes(im, &o, &run);
    if (res == PTR_OK && !node->has_radius)
        note_skipped(im, &o, &mesh, run.surface->skipped * run.instances);
    Instance first;
    int warned = 0;
    if (res == PTR_OK && instance_at(&run, 0, &first) != NO_FAULT)
        res = slot_error(im, &run, &instance, 0);
    if (res == PTR_OK)
        res = run_mesh(im, &instance, &run, &first, &warned);
    if (res == PTR_OK)
        res = start_run(im, &run);
    if (res == PTR_OK) {
        convert_run(im, &run);
        const size_t failed = atomic_load(&run.failed);
        if (failed != SIZE_MAX)
            res = slot_error(im, &run, &instance, failed);
        else if (atomic_load(&run.nonuniform))
            warn_nonuniform(im, &o, &warned);
    }
    free(run.sets);
    free(run.surface_materials);
    return res;
}

/* The projection of a glTF camera, in the scene's terms; 0 if a value is out
 * of the range glTF allows. */
static int camera_lens(Importer *im, const GltfCamera *cam, const char *name, PtrCamera *lens)
{
    double focus = cam->has_focus_distance ? cam->focus_distance : 1.0;
    double aperture = cam->has_aperture ? cam->aperture : 0.0;
    if (!(focus > 0) || !isfinite(focus) || !(aperture >= 0) || !isfinite(aperture))
        return 0;
    if (cam->perspective) {
        double yfov_deg = cam->yfov * 180.0 / 3.14159265358979323846;
        *lens = (PtrCamera){
            .vfov_deg = (float)yfov_deg, .aperture = (float)aperture,
            .focus_distance = (float)focus, .aspect = (float)cam->aspect_ratio,
        };
        return yfov_deg > 0 && yfov_deg < 180 && cam->aspect_ratio >= 0;
    }
    if (aperture > 0 && !im->builder.override) /* only of the camera used */
        ptr_warn(im->warnings, "%s: camera '%s' is orthographic, which has no depth of field: "
                 "extras.aperture is ignored", im->path, name);
    *lens = (PtrCamera){
        .projection = PTR_PROJECTION_ORTHOGRAPHIC, .focus_distance = (float)focus,
        .ymag = (float)cam->ymag, .znear = (float)cam->znear,
        .aspect = (float)(cam->xmag / cam->ymag),
    };
    im->ortho_name = name;
    im->zfar = cam->zfar;
    return cam->xmag > 0 && cam->ymag > 0 && isfinite(cam->xmag) && isfinite(cam->ymag) &&
           cam->znear >= 0 && cam->zfar > cam->znear && isfinite(cam->zfar) &&
           isfinite(lens->aspect) && lens->aspect > 0;
}

static PtrResult take_camera(Importer *im, const GltfNode *node, const Mat4 *world)
{
    if (im->camera_found)
        return PTR_OK;
    GltfCamera cam;
    gltf_doc_camera(im->doc, (size_t)node->camera, &cam);
    if (im->camera_name && strcmp(im->camera_name, node->name) &&
        strcmp(im->camera_name, cam.name))
        return PTR_OK;
    const char *name = label(cam.name, label(node->name, "unnamed"));
    const double origin[3] = { 0, 0, 0 };
    double eye[3];
    mat4_point(world, origin, eye);
    double fwd_len = column_length(world, 2), up_len = column_length(world, 1);
    PtrCamera lens;
    if (!camera_lens(im, &cam, name, &lens) || !all_finite(world->m, 16) || !(fwd_len > 0) ||
        !(up_len > 0))
        return ptr_error_set(im->err, PTR_ERR_SCENE_INVALID,
                             "%s: camera '%s' has a degenerate transform or a value out of range",
                             im->path, name);
    double target[3], up[3];
    for (int k = 0; k < 3; k++) {
        /* A glTF camera looks down its local -Z with +Y up. */
        target[k] = eye[k] - world->m[8 + k] / fwd_len * lens.focus_distance;
        up[k] = world->m[4 + k] / up_len;
    }
    ptr_builder_set_camera(&im->builder, eye, target, up, &lens);
    im->camera_found = 1;
    return PTR_OK;
}

/* Rays are not cut at an orthographic camera's far plane (a path tracer's
 * rays go on to the sky): warns, naming the camera, if a sphere reaches
 * beyond it, and so shows where a rasteriser would clip it. */
static void check_far_plane(Importer *im)
{
    const PtrSceneBuilder *b = &im->builder;
    if (!im->ortho_name || b->override)
        return;
    double fwd[3], len = 0;
    for (int k = 0; k < 3; k++) {
        fwd[k] = b->target[k] - b->eye[k];
        len += fwd[k] * fwd[k];
    }
    len = sqrt(len);
    size_t beyond = 0;
    for (size_t i = 0; i < b->count; i++) {
        const double *s = &b->spheres[4 * i];
        double depth = 0;
        for (int k = 0; k < 3; k++)
            depth += (s[k] - b->eye[k]) * fwd[k] / len;
        beyond += depth + s[3] > im->zfar;
    }
    if (beyond)
        ptr_warn(im->warnings, "%s: camera '%s': ptr does not clip at zfar (%g); %zu sphere%s "
                 "beyond it %s seen", im->path, im->ortho_name, im->zfar, beyond,
                 beyond == 1 ? "" : "s", beyond == 1 ? "is" : "are");
}

static uint64_t add_saturating(uint64_t a, uint64_t b)
{
    return a > UINT64_MAX - b ? UINT64_MAX : a + b;
}

static uint64_t mul_saturating(uint64_t a, uint64_t b)
{
    return b && a > UINT64_MAX / b ? UINT64_MAX : a * b;
}

/* The spheres of a node (o): its surface's and its points', once per
 * instance, from the surface's components and the accessors' counts. */
static PtrResult node_sphere_count(Importer *im, const Origin *o, const GltfNode *node,
                                   uint64_t *out)
{
    GltfMesh mesh;
    gltf_doc_mesh(im->doc, (size_t)node->mesh, &mesh);
    const SurfaceSpheres *surface = NULL;
    if (!node->has_radius) {
        PtrResult res = surface_spheres(im, o, (size_t)node->mesh, &surface);
        if (res != PTR_OK)
            return res;
    }
    uint64_t spheres = surface ? surface->count : (uint64_t)mesh.has_surface;
    for (size_t p = 0; p < mesh.primitive_count; p++) {
        GltfPrimitive prim;
        gltf_doc_primitive(im->doc, (size_t)node->mesh, p, &prim);
        if (prim.points && prim.position >= 0) {
            GltfAccessor a;
            gltf_doc_accessor(im->doc, (size_t)prim.position, &a);
            spheres = add_saturating(spheres, a.count);
        }
    }
    const GltfInstancing *in = &node->instances;
    const int per_instance = in->translation >= 0 ? in->translation
                           : in->rotation >= 0    ? in->rotation
                                                  : in->scale;
    *out = spheres;
    if (!node->instanced || per_instance < 0)
        return PTR_OK;
    GltfAccessor a;
    gltf_doc_accessor(im->doc, (size_t)per_instance, &a);
    *out = mul_saturating(spheres, a.count);
    return PTR_OK;
}

/* What walk_nodes does at each node, under its world transform. */
typedef PtrResult (*NodeVisit)(Importer *im, size_t index, const GltfNode *node,
                               const Mat4 *world, void *user);

/* The spheres the default scene will hold, counted before anything is read
 * or allocated for them (user: a uint64_t, saturating): instances can
 * multiply a small file's accessors into more spheres than the machine
 * holds. */
static PtrResult count_spheres(Importer *im, size_t index, const GltfNode *node,
                               const Mat4 *world, void *user)
{
    (void)world;
    uint64_t *spheres = user, count = 0;
    if (node->mesh < 0)
        return PTR_OK;
    const Origin o = { index, label(node->name, "unnamed"), NULL, 0 };
    PtrResult res = node_sphere_count(im, &o, node, &count);
    *spheres = add_saturating(*spheres, count);
    return res;
}

/* The node's spheres and camera into the scene. */
static PtrResult import_node(Importer *im, size_t index, const GltfNode *node, const Mat4 *world,
                             void *user)
{
    (void)user;
    PtrResult res = PTR_OK;
    if (node->mesh >= 0)
        res = add_node_spheres(im, index, node, world);
    if (res == PTR_OK && node->camera >= 0)
        res = take_camera(im, node, world);
    return res;
}

/* Depth-first, pre-order, over the default scene, visiting each node; glTF
 * requires the nodes to form trees, so a node met twice is an error (a cycle
 * or a shared child). */
static PtrResult walk_nodes(Importer *im, const GltfScene *gs, NodeVisit visit, void *user)
{
    size_t n = gltf_doc_node_count(im->doc);
    Mat4 *world = malloc((n ? n : 1) * sizeof *world);
    int *stack = malloc((n ? n : 1) * sizeof *stack);
    int *parent = malloc((n ? n : 1) * sizeof *parent);
    unsigned char *seen = calloc(n ? n : 1, 1);
    PtrResult res = PTR_OK;
    if (!world || !stack || !parent || !seen) {
        res = ptr_error_set(im->err, PTR_ERR_NOMEM, "%s: out of memory", im->path);
        goto done;
    }
    for (size_t r = 0; r < gs->root_count && res == PTR_OK; r++) {
        size_t top = 0;
        stack[top++] = gs->roots[r];
        parent[gs->roots[r]] = -1;
        while (top > 0 && res == PTR_OK) {
            int index = stack[--top];
            GltfNode node;
            gltf_doc_node(im->doc, (size_t)index, &node);
            if (seen[index]) {
                res = ptr_error_set(im->err, PTR_ERR_SCENE_INVALID,
                                    "%s: node %d ('%s') is reached twice: the node graph has a "
                                    "cycle or a node with two parents",
                                    im->path, index, label(node.name, "unnamed"));
                break;
            }
            seen[index] = 1;
            Mat4 local = node_local(&node);
            world[index] = parent[index] < 0 ? local : mat4_mul(&world[parent[index]], &local);
            if (!all_finite(world[index].m, 16)) {
                res = ptr_error_set(im->err, PTR_ERR_SCENE_INVALID,
                                    "%s: node %d ('%s') has a non-finite transform", im->path,
                                    index, label(node.name, "unnamed"));
                break;
            }
            res = visit(im, (size_t)index, &node, &world[index], user);
            for (size_t c = node.child_count; c-- > 0 && res == PTR_OK;) {
                int child = node.children[c];
                if (seen[child] || top >= n) {
                    GltfNode bad;
                    gltf_doc_node(im->doc, (size_t)child, &bad);
                    res = ptr_error_set(im->err, PTR_ERR_SCENE_INVALID,
                                        "%s: node %d ('%s') is reached twice: the node graph "
                                        "has a cycle or a node with two parents",
                                        im->path, child, label(bad.name, "unnamed"));
                    break;
                }
                parent[child] = index;
                stack[top++] = child;
            }
        }
    }
done:
    free(world);
    free(stack);
    free(parent);
    free(seen);
    return res;
}

static PtrResult read_scene_extras(Importer *im, const GltfScene *gs)
{
    PtrScene *scene = im->scene;
    if (gs->sky_invalid ||
        (gs->sky_name && ptr_sky_parse(gs->sky_name, &scene->sky, NULL) != PTR_OK) ||
        (gs->sky_name && scene->sky.kind == PTR_SKY_CONSTANT))
        return ptr_error_set(im->err, PTR_ERR_SCENE_INVALID,
                             "%s: scene extras.sky must be \"gradient\", \"black\" or [r, g, b]",
                             im->path);
    if (gs->has_sky_rgb) {
        if (!all_finite(gs->sky_rgb, 3) || gs->sky_rgb[0] < 0 || gs->sky_rgb[1] < 0 ||
            gs->sky_rgb[2] < 0)
            return ptr_error_set(im->err, PTR_ERR_SCENE_INVALID,
                                 "%s: scene extras.sky colour must be finite and not negative",
                                 im->path);
        scene->sky = (PtrSky){ .kind = PTR_SKY_CONSTANT, .radiance = vec_from(gs->sky_rgb) };
    }
    if (gs->resolution_invalid ||
        (gs->has_resolution &&
         (gs->resolution[0] <= 0 || gs->resolution[0] > MAX_RESOLUTION ||
          gs->resolution[1] <= 0 || gs->resolution[1] > MAX_RESOLUTION)))
        return ptr_error_set(im->err, PTR_ERR_SCENE_INVALID,
                             "%s: scene extras.resolution must be [width, height], "
                             "whole numbers from 1 to %d", im->path, MAX_RESOLUTION);
    if (gs->has_resolution) {
        scene->width = gs->resolution[0];
        scene->height = gs->resolution[1];
    }
    return PTR_OK;
}

PtrResult ptr_import_gltf(const char *path, const PtrImportOptions *options,
                          PtrScene *scene, PtrStrings *warnings, PtrError *err)
{
    GltfDoc *doc = gltf_doc_load(path, err);
    if (!doc)
        return err->code;

    Importer im = {
        .path = path, .doc = doc, .scene = scene, .warnings = warnings, .err = err,
        .camera_name = options ? options->camera_name : NULL,
        .default_material = UINT32_MAX,
        .value_name = options ? options->value_attribute : NULL,
    };
    ptr_builder_init(&im.builder, scene, options);
    PtrResult res = options && options->textures.decode
                        ? gltf_textures_new(doc, path, &options->textures, &im.textures, err)
                        : PTR_OK;
    size_t materials = gltf_doc_material_count(doc), meshes = gltf_doc_mesh_count(doc);
    im.material_index = malloc((materials ? materials : 1) * sizeof *im.material_index);
    im.surfaces = calloc(meshes ? meshes : 1, sizeof *im.surfaces);
    for (im.surface_slots = 16; im.surface_slots < 2 * meshes;)
        im.surface_slots *= 2;
    im.surface_table = malloc(im.surface_slots * sizeof *im.surface_table);
    GltfScene gs;
    if (res == PTR_OK && (!im.material_index || !im.surfaces || !im.surface_table)) {
        res = ptr_error_set(err, PTR_ERR_NOMEM, "%s: out of memory", path);
    } else if (res == PTR_OK && !gltf_doc_scene(doc, &gs)) {
        res = ptr_error_set(err, PTR_ERR_SCENE_INVALID, "%s: the file has no scene", path);
    } else if (res == PTR_OK) {
        for (size_t i = 0; i < materials; i++)
            im.material_index[i] = UINT32_MAX;
        memset(im.surface_table, 0xff, im.surface_slots * sizeof *im.surface_table);
        res = read_scene_extras(&im, &gs);
        uint64_t spheres = 0;
        if (res == PTR_OK)
            res = walk_nodes(&im, &gs, count_spheres, &spheres);
        if (res == PTR_OK)
            res = ptr_import_check_memory(path, spheres, err);
        if (res == PTR_OK && ptr_builder_reserve(&im.builder, (size_t)spheres, NULL) != PTR_OK)
            res = ptr_error_set(err, PTR_ERR_NOMEM, "%s: out of memory", path);
        if (res == PTR_OK)
            res = walk_nodes(&im, &gs, import_node, NULL);
    }
    if (res == PTR_OK && im.camera_name && !im.camera_found && !(options && options->camera))
        res = ptr_error_set(err, PTR_ERR_SCENE_INVALID,
                            "%s: no camera named '%s' in the default scene", path,
                            im.camera_name);
    if (res == PTR_OK && im.value_name && !im.builder.values) {
        char names[256];
        gltf_doc_custom_attributes(doc, names, sizeof names);
        res = ptr_error_set(err, PTR_ERR_SCENE_INVALID,
                            "%s: no instance or point attribute '%s' (--color-by); %s%s", path,
                            im.value_name, *names ? "the file has " : "the file has none",
                            names);
    }
    if (res == PTR_OK)
        check_far_plane(&im);
    if (res == PTR_OK && im.skipped)
        ptr_warn(warnings, "%s: %zu mesh part%s not drawn: %s not a sphere (docs/scenes.md, "
                 "\"Spheres\"): %s%s", path, im.skipped, im.skipped == 1 ? "" : "s",
                 im.skipped == 1 ? "it is" : "they are", im.skipped_names,
                 im.skipped_more ? ", ..." : "");
    if (res == PTR_OK && im.varying)
        ptr_warn(warnings, "%s: %zu sphere%s textures or vertex colours that vary over %s: "
                 "each takes their mean", path, im.varying,
                 im.varying == 1 ? " has" : "s have", im.varying == 1 ? "it" : "them");
    for (size_t i = 0; options && options->dependencies && i < gltf_doc_file_count(doc); i++)
        ptr_warn(options->dependencies, "%s", gltf_doc_file(doc, i));
    /* The file's buffers go before the scene's arrays are filled. */
    gltf_doc_free(doc);
    free(im.material_index);
    for (size_t m = 0; im.surfaces && m < meshes; m++) {
        free(im.surfaces[m].spheres);
        free(im.surfaces[m].primitives);
        free(im.surfaces[m].materials);
    }
    free(im.made);
    gltf_textures_free(im.textures);
    free(im.surfaces);
    free(im.surface_table);
    if (res == PTR_OK)
        res = ptr_import_finish(&im.builder, path, err);
    ptr_builder_free(&im.builder);
    return res;
}
