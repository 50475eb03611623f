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
#include "importer_internal.h"

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
    const char *value_name; /* the attribute --color-by asks for, or NULL */
} Importer;

static const char *label(const char *name, const char *fallback)
{
    return name && *name ? name : fallback;
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
        if (g.has_texture && !im->warned_texture) {
            im->warned_texture = 1;
            ptr_warn(im->warnings, "%s: textures are ignored (first seen on material '%s')",
                     im->path, label(g.name, "unnamed"));
        }
        double emission[3] = { g.emissive[0] * g.emissive_strength,
                               g.emissive[1] * g.emissive_strength,
                               g.emissive[2] * g.emissive_strength };
        if (!all_finite(g.base_color, 4) || !all_finite(emission, 3) || !isfinite(g.ior) ||
            !isfinite(g.roughness) || !isfinite(g.metallic) || !isfinite(g.transmission) ||
            !(g.ior > 0.0) || emission[0] < 0 || emission[1] < 0 || emission[2] < 0)
            return ptr_error_set(im->err, PTR_ERR_SCENE_INVALID,
                                 "%s: material %d ('%s') has a value out of range", im->path,
                                 gltf_index, label(g.name, "unnamed"));
        m.albedo = vec_from(g.base_color);
        m.emission = vec_from(emission);
        if (g.transmission > 0.0) {
            m.kind = PTR_MATERIAL_DIELECTRIC;
            m.ior = (float)g.ior;
        } else if (g.metallic >= 0.5) {
            m.kind = PTR_MATERIAL_METAL;
            m.fuzz = (float)g.roughness;
        }
    }
    if (ptr_scene_add_material(im->scene, &m, slot, NULL) != PTR_OK)
        return ptr_error_set(im->err, PTR_ERR_NOMEM, "%s: out of memory", im->path);
    *out = *slot;
    return PTR_OK;
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

static double largest_scale(const Mat4 *world, Importer *im, const Origin *o, int *warned)
{
    int nonuniform = 0;
    double scale = axis_scale(world, &nonuniform);
    if (nonuniform)
        warn_nonuniform(im, o, warned);
    return scale;
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

static PtrResult add_sphere(Importer *im, const Origin *o, const double centre[3], double radius,
                            uint32_t material, const double *color, const double *value)
{
    if (sphere_fault(centre, radius))
        return part_error(im, o, sphere_fault_text);
    if (ptr_builder_add_sphere(&im->builder, centre, radius, material, NULL) != PTR_OK ||
        (color && ptr_builder_set_color(&im->builder, color, NULL) != PTR_OK) ||
        (value && ptr_builder_set_value(&im->builder, *value, NULL) != PTR_OK))
        return ptr_error_set(im->err, PTR_ERR_NOMEM, "%s: out of memory", im->path);
    return PTR_OK;
}

/* The sphere of a node's mesh surface under world, where the node has a
 * radius or the mesh bounds; *nonuniform set if world's scale is not
 * uniform. */
static void surface_sphere(const GltfNode *node, const GltfMesh *mesh, const Mat4 *world,
                           double centre[3], double *radius, int *nonuniform)
{
    if (node->has_radius) {
        const double origin[3] = { 0, 0, 0 };
        mat4_point(world, origin, centre);
        *radius = node->radius;
        return;
    }
    double local[3], extent = 0.0;
    for (int k = 0; k < 3; k++) {
        local[k] = 0.5 * (mesh->min[k] + mesh->max[k]);
        extent = fmax(extent, mesh->max[k] - mesh->min[k]);
    }
    mat4_point(world, local, centre);
    *radius = 0.5 * extent * axis_scale(world, nonuniform);
}

static PtrResult add_surface_sphere(Importer *im, const Origin *o, const GltfNode *node,
                                    const GltfMesh *mesh, const Mat4 *world, const double *color,
                                    const double *value, int *warned)
{
    if (!node->has_radius && !mesh->has_bounds)
        return ptr_error_set(im->err, PTR_ERR_SCENE_INVALID,
                             "%s: node %zu ('%s'): mesh %d has no POSITION min/max bounds",
                             im->path, o->node_index, o->node_name, node->mesh);
    double centre[3], radius;
    int nonuniform = 0;
    surface_sphere(node, mesh, world, centre, &radius, &nonuniform);
    if (nonuniform)
        warn_nonuniform(im, o, warned);
    uint32_t material = 0;
    PtrResult res = map_material(im, mesh->material, &material);
    return res != PTR_OK ? res : add_sphere(im, o, centre, radius, material, color, value);
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
 * (docs/scenes.md); refused unless finite. o names element i. */
static PtrResult read_value(Importer *im, const Origin *o, const GltfAccessor *a, size_t i,
                            double *value)
{
    double v[4], sum = 0;
    element(a, i, v);
    for (int c = 0; c < a->components; c++)
        sum += v[c] * v[c];
    *value = a->components == 1 ? v[0] : sqrt(sum);
    if (isfinite(*value))
        return PTR_OK;
    char where[160];
    origin_text(o, where, sizeof where);
    return ptr_error_set(im->err, PTR_ERR_SCENE_INVALID, "%s: %s: attribute '%s' is not finite",
                         im->path, where, im->value_name);
}

/* Every this many instances or points, the import gives back the pages of
 * the file it has read (see gltf_doc_release). */
enum { RELEASE_STEP = 1 << 16 };

/* Called after element i of count of the accessors given (NULL: absent) is
 * read: at every RELEASE_STEP-th and the last, those read since *released
 * are given back. */
static void release_read(const Importer *im, size_t i, size_t count, size_t *released,
                         const GltfAccessor *const *accessors, size_t n)
{
    if ((i + 1) % RELEASE_STEP != 0 && i + 1 != count)
        return;
    for (size_t k = 0; k < n; k++)
        if (accessors[k])
            gltf_doc_release(im->doc, accessors[k], *released, i + 1);
    *released = i + 1;
}

/* Instanced nodes of this many instances of a plain sphere, and POINTS
 * primitives of this many points, with no --color-by value, are turned into
 * spheres on all cores, PARALLEL_BLOCK at a time (the file's pages read are
 * given back after each). */
enum { PARALLEL_PARTS = 1 << 15, PARALLEL_BLOCK = 1 << 20 };

/* Keeps in *failed the least part index that fails: the one a serial import
 * reports, whichever thread meets it first. */
static void note_failure(atomic_size_t *failed, size_t i)
{
    size_t seen = atomic_load(failed);
    while (i < seen && !atomic_compare_exchange_weak(failed, &seen, i))
        ;
}

/* Runs convert over parts 0 .. count - 1 on all cores, a block at a time,
 * giving back the pages of the n accessors read (NULL entries: none) after
 * each, and stops after the block where a part failed (*failed below
 * SIZE_MAX). */
static void convert_in_blocks(Importer *im, size_t count, void (*convert)(void *, size_t, size_t),
                              void *run, atomic_size_t *failed,
                              const GltfAccessor *const *read, size_t n)
{
    const int threads = ptr_online_cpus();
    for (size_t begin = 0; begin < count; begin += PARALLEL_BLOCK) {
        const size_t end = count - begin > PARALLEL_BLOCK ? begin + PARALLEL_BLOCK : count;
        ptr_parallel_ranges(threads, begin, end, convert, run);
        for (size_t k = 0; k < n; k++)
            if (read[k])
                gltf_doc_release(im->doc, read[k], begin, end);
        if (atomic_load(failed) != SIZE_MAX)
            break;
    }
}

/* A point's colour: its COLOR_0 c (NULL: none) times the colour of the
 * instance it is part of (NULL: none); one of them is given. */
static void point_color(const double *c, const double *instance, double rgb[3])
{
    for (int k = 0; k < 3; k++)
        rgb[k] = c ? c[k] * (instance ? instance[k] : 1.0) : instance[k];
}

typedef struct PointRun {
    PtrSceneBuilder *builder;
    const GltfAccessor *pos, *rad, *col; /* rad, col NULL: absent */
    const Mat4 *world;
    const double *color;  /* the instance's, if any */
    double radius, scale; /* without rad, the node's radius; world's largest axis scale */
    uint32_t material;
    size_t first;         /* the builder's sphere for point 0 */
    atomic_size_t failed; /* the first point that cannot be a sphere; SIZE_MAX: none */
} PointRun;

/* Points begin .. end - 1 as add_points would add them one by one. */
static void convert_points(void *arg, size_t begin, size_t end)
{
    PointRun *run = arg;
    for (size_t i = begin; i < end; i++) {
        double p[4], r[4], centre[3];
        element(run->pos, i, p);
        mat4_point(run->world, p, centre);
        if (run->rad)
            element(run->rad, i, r);
        else
            r[0] = run->radius;
        const double radius = r[0] * run->scale;
        if (sphere_fault(centre, radius)) {
            note_failure(&run->failed, i);
            break;
        }
        double c[4], rgb[3];
        const int colored = run->col || run->color;
        if (run->col)
            element(run->col, i, c);
        if (colored)
            point_color(run->col ? c : NULL, run->color, rgb);
        ptr_builder_fill_sphere(run->builder, run->first + i, centre, radius, run->material,
                                colored ? rgb : NULL);
    }
}

/* The spheres of a POINTS primitive under world (times color, if any), each
 * with its own value of the attribute value_index (-1: none) names, else
 * value (if any). */
static PtrResult add_points(Importer *im, const Origin *node_origin, const GltfNode *node,
                            const GltfPrimitive *prim, int value_index, const Mat4 *world,
                            const double *color, const double *value, int *warned)
{
    if (prim->radius < 0 && !node->has_radius)
        return ptr_error_set(im->err, PTR_ERR_SCENE_INVALID,
                             "%s: node %zu ('%s') has POINTS without a _RADIUS attribute or an "
                             "extras.radius", im->path, node_origin->node_index,
                             node_origin->node_name);
    if (prim->position < 0)
        return ptr_error_set(im->err, PTR_ERR_SCENE_INVALID,
                             "%s: node %zu ('%s') has POINTS without POSITION", im->path,
                             node_origin->node_index, node_origin->node_name);
    if (prim->draco)
        return ptr_error_set(im->err, PTR_ERR_SCENE_INVALID,
                             "%s: node %zu ('%s') has POINTS compressed by "
                             "KHR_draco_mesh_compression, of which ptr reads only the bounds of "
                             "meshes", im->path, node_origin->node_index, node_origin->node_name);
    size_t count = 0;
    GltfAccessor pos, rad, col;
    PtrResult res = attribute_accessor(im, node_origin, "POSITION", prim->position, 3, 3,
                                       QUANTIZED, &count, &pos);
    if (res == PTR_OK && prim->radius >= 0)
        res = attribute_accessor(im, node_origin, "_RADIUS", prim->radius, 1, 1, FLOATS, &count,
                                 &rad);
    if (res == PTR_OK && prim->color >= 0)
        res = attribute_accessor(im, node_origin, "COLOR_0", prim->color, 3, 4,
                                 FLOATS_OR_UNSIGNED, &count, &col);
    GltfAccessor val;
    if (res == PTR_OK && value_index != -1)
        res = value_accessor(im, node_origin, "point", value_index, &count, &val);
    uint32_t material = 0;
    if (res == PTR_OK)
        res = map_material(im, prim->material, &material);
    if (res != PTR_OK)
        return res;
    const double scale = largest_scale(world, im, node_origin, warned);
    Origin o = *node_origin;
    o.part = "point";
    /* Points an instance repeats are read again by the next one. */
    const GltfAccessor *read[] = { &pos, prim->radius >= 0 ? &rad : NULL,
                                   prim->color >= 0 ? &col : NULL,
                                   value_index != -1 ? &val : NULL };
    const size_t release = node_origin->part ? 0 : sizeof read / sizeof read[0];
    if (count >= PARALLEL_PARTS && value_index == -1 && !value) {
        PointRun run = { .builder = &im->builder, .pos = &pos,
                         .rad = prim->radius >= 0 ? &rad : NULL,
                         .col = prim->color >= 0 ? &col : NULL, .world = world, .color = color,
                         .radius = node->radius, .scale = scale, .material = material };
        atomic_init(&run.failed, SIZE_MAX);
        if (ptr_builder_add_spheres(&im->builder, count, run.col || color, &run.first, NULL) != PTR_OK)
            return ptr_error_set(im->err, PTR_ERR_NOMEM, "%s: out of memory", im->path);
        convert_in_blocks(im, count, convert_points, &run, &run.failed, read, release);
        o.part_index = atomic_load(&run.failed);
        return o.part_index == SIZE_MAX ? PTR_OK : part_error(im, &o, sphere_fault_text);
    }
    size_t released = 0;
    for (size_t i = 0; i < count && res == PTR_OK; i++) {
        double p[4], r[4], c[4], centre[3], rgb[3], own_value;
        element(&pos, i, p);
        mat4_point(world, p, centre);
        if (prim->radius >= 0)
            element(&rad, i, r);
        else
            r[0] = node->radius;
        if (prim->color >= 0) {
            element(&col, i, c);
            point_color(c, color, rgb);
        }
        o.part_index = i;
        if (value_index != -1)
            res = read_value(im, &o, &val, i, &own_value);
        if (res == PTR_OK)
            res = add_sphere(im, &o, centre, r[0] * scale, material,
                             prim->color >= 0 ? rgb : color,
                             value_index != -1 ? &own_value : value);
        release_read(im, i, count, &released, read, release);
    }
    return res;
}

/* A node's spheres under world: its surface's and its points'. */
static PtrResult add_mesh_spheres(Importer *im, const Origin *o, const GltfNode *node,
                                  const GltfMesh *mesh, const Mat4 *world, const double *color,
                                  const double *value, int *warned)
{
    PtrResult res = PTR_OK;
    if (mesh->has_surface)
        res = add_surface_sphere(im, o, node, mesh, world, color, value, warned);
    /* Looked up only where there are points: an instance of a plain sphere
     * is a million of these calls. */
    for (size_t p = 0; mesh->point_primitives && p < mesh->primitive_count && res == PTR_OK;
         p++) {
        GltfPrimitive prim;
        gltf_doc_primitive(im->doc, (size_t)node->mesh, p, &prim);
        int value_index = im->value_name ? gltf_doc_primitive_attribute(
                                               im->doc, (size_t)node->mesh, p, im->value_name)
                                         : -1;
        if (prim.points)
            res = add_points(im, o, node, &prim, value_index, world, color, value, warned);
    }
    return res;
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

typedef struct InstanceRun {
    PtrSceneBuilder *builder;
    const GltfNode *node;
    const GltfMesh *mesh;
    const Mat4 *world;
    const GltfAccessor *t, *r, *s, *c; /* NULL: absent */
    uint32_t material;
    size_t first;           /* the builder's sphere for instance 0 */
    atomic_size_t failed;   /* the first instance that cannot be a sphere; SIZE_MAX: none */
    atomic_int nonuniform;
} InstanceRun;

/* Instances begin .. end - 1 as add_instances would add them one by one. */
static void convert_instances(void *arg, size_t begin, size_t end)
{
    InstanceRun *run = arg;
    int nonuniform = 0;
    for (size_t i = begin; i < end; i++) {
        Mat4 local, world;
        double centre[3], radius;
        if (!instance_local(run->t, run->r, run->s, i, &local)) {
            note_failure(&run->failed, i);
            break;
        }
        world = mat4_mul(run->world, &local);
        surface_sphere(run->node, run->mesh, &world, centre, &radius, &nonuniform);
        if (sphere_fault(centre, radius)) {
            note_failure(&run->failed, i);
            break;
        }
        double rgb[4];
        if (run->c)
            element(run->c, i, rgb);
        ptr_builder_fill_sphere(run->builder, run->first + i, centre, radius, run->material,
                                run->c ? rgb : NULL);
    }
    if (nonuniform)
        atomic_store(&run->nonuniform, 1);
}

/* add_instances' loop for count instances of a plain sphere (accessors t,
 * r, s, c: NULL where absent), the same spheres, warnings and first error. */
static PtrResult add_instances_parallel(Importer *im, const Origin *instance,
                                        const GltfNode *node, const GltfMesh *mesh,
                                        const Mat4 *world, const GltfAccessor *const tsrc[4],
                                        size_t count, int *warned)
{
    InstanceRun run = { .builder = &im->builder, .node = node, .mesh = mesh, .world = world,
                        .t = tsrc[0], .r = tsrc[1], .s = tsrc[2], .c = tsrc[3] };
    atomic_init(&run.failed, SIZE_MAX);
    atomic_init(&run.nonuniform, 0);
    PtrResult res = map_material(im, mesh->material, &run.material);
    if (res == PTR_OK &&
        ptr_builder_add_spheres(&im->builder, count, run.c != NULL, &run.first, NULL) != PTR_OK)
        res = ptr_error_set(im->err, PTR_ERR_NOMEM, "%s: out of memory", im->path);
    if (res != PTR_OK)
        return res;
    convert_in_blocks(im, count, convert_instances, &run, &run.failed, tsrc, 4);
    const size_t failed = atomic_load(&run.failed);
    if (failed != SIZE_MAX) {
        Origin at = *instance;
        at.part_index = failed;
        Mat4 local;
        return part_error(im, &at, instance_local(run.t, run.r, run.s, failed, &local)
                                       ? sphere_fault_text : transform_fault_text);
    }
    if (atomic_load(&run.nonuniform))
        warn_nonuniform(im, instance, warned);
    return PTR_OK;
}

/* EXT_mesh_gpu_instancing: the node's spheres once per instance. */
static PtrResult add_instances(Importer *im, const Origin *o, const GltfNode *node,
                               const GltfMesh *mesh, const Mat4 *world, int *warned)
{
    const GltfInstancing *in = &node->instances;
    if (in->translation < 0 && in->rotation < 0 && in->scale < 0)
        return ptr_error_set(im->err, PTR_ERR_SCENE_INVALID,
                             "%s: node %zu ('%s') has EXT_mesh_gpu_instancing without "
                             "TRANSLATION, ROTATION or SCALE", im->path, o->node_index,
                             o->node_name);
    size_t count = 0;
    GltfAccessor t, r, s, c;
    PtrResult res = PTR_OK;
    if (in->translation >= 0)
        res = attribute_accessor(im, o, "TRANSLATION", in->translation, 3, 3, QUANTIZED, &count,
                                 &t);
    if (res == PTR_OK && in->rotation >= 0)
        res = attribute_accessor(im, o, "ROTATION", in->rotation, 4, 4, FLOATS_OR_SIGNED, &count,
                                 &r);
    if (res == PTR_OK && in->scale >= 0)
        res = attribute_accessor(im, o, "SCALE", in->scale, 3, 3, QUANTIZED, &count, &s);
    if (res == PTR_OK && in->color >= 0)
        res = attribute_accessor(im, o, "_COLOR_0", in->color, 3, 4, FLOATS_OR_UNSIGNED, &count,
                                 &c);
    int value_index = im->value_name
                          ? gltf_doc_instance_attribute(im->doc, o->node_index, im->value_name)
                          : -1;
    GltfAccessor v;
    if (res == PTR_OK && value_index != -1)
        res = value_accessor(im, o, "instance", value_index, &count, &v);
    Origin instance = *o;
    instance.part = "instance";
    if (res == PTR_OK && count >= PARALLEL_PARTS && value_index == -1 &&
        mesh->has_surface && !mesh->point_primitives && (node->has_radius || mesh->has_bounds)) {
        const GltfAccessor *const tsrc[4] = { in->translation >= 0 ? &t : NULL,
                                              in->rotation >= 0 ? &r : NULL,
                                              in->scale >= 0 ? &s : NULL,
                                              in->color >= 0 ? &c : NULL };
        return add_instances_parallel(im, &instance, node, mesh, world, tsrc, count, warned);
    }
    const GltfAccessor *read[] = { in->translation >= 0 ? &t : NULL, in->rotation >= 0 ? &r : NULL,
                                   in->scale >= 0 ? &s : NULL, in->color >= 0 ? &c : NULL,
                                   value_index != -1 ? &v : NULL };
    size_t released = 0;
    for (size_t i = 0; i < count && res == PTR_OK; i++) {
        Mat4 local, instance_world;
        instance.part_index = i;
        if (!instance_local(in->translation >= 0 ? &t : NULL, in->rotation >= 0 ? &r : NULL,
                            in->scale >= 0 ? &s : NULL, i, &local))
            return part_error(im, &instance, transform_fault_text);
        instance_world = mat4_mul(world, &local);
        double color[4], value;
        if (in->color >= 0)
            element(&c, i, color);
        if (value_index != -1)
            res = read_value(im, &instance, &v, i, &value);
        if (res == PTR_OK)
            res = add_mesh_spheres(im, &instance, node, mesh, &instance_world,
                                   in->color >= 0 ? color : NULL,
                                   value_index != -1 ? &value : NULL, warned);
        release_read(im, i, count, &released, read, sizeof read / sizeof read[0]);
    }
    return res;
}

static PtrResult add_node_spheres(Importer *im, size_t node_index, const GltfNode *node,
                                  const Mat4 *world)
{
    GltfMesh mesh;
    gltf_doc_mesh(im->doc, (size_t)node->mesh, &mesh);
    const Origin o = { node_index, label(node->name, "unnamed"), NULL, 0 };
    int warned = 0;
    if (node->instanced)
        return add_instances(im, &o, node, &mesh, world, &warned);
    return add_mesh_spheres(im, &o, node, &mesh, world, NULL, NULL, &warned);
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

/* The spheres of a node: its surface's and its points', once per instance,
 * from the accessors' counts alone. */
static uint64_t node_sphere_count(const Importer *im, const GltfNode *node)
{
    GltfMesh mesh;
    gltf_doc_mesh(im->doc, (size_t)node->mesh, &mesh);
    uint64_t spheres = mesh.has_surface ? 1 : 0;
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
    if (!node->instanced || per_instance < 0)
        return spheres;
    GltfAccessor a;
    gltf_doc_accessor(im->doc, (size_t)per_instance, &a);
    return mul_saturating(spheres, a.count);
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
    (void)index, (void)world;
    uint64_t *spheres = user;
    if (node->mesh >= 0)
        *spheres = add_saturating(*spheres, node_sphere_count(im, node));
    return PTR_OK;
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
    size_t materials = gltf_doc_material_count(doc);
    im.material_index = malloc((materials ? materials : 1) * sizeof *im.material_index);
    PtrResult res = PTR_OK;
    GltfScene gs;
    if (!im.material_index) {
        res = ptr_error_set(err, PTR_ERR_NOMEM, "%s: out of memory", path);
    } else if (!gltf_doc_scene(doc, &gs)) {
        res = ptr_error_set(err, PTR_ERR_SCENE_INVALID, "%s: the file has no scene", path);
    } else {
        for (size_t i = 0; i < materials; i++)
            im.material_index[i] = UINT32_MAX;
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
    for (size_t i = 0; options && options->dependencies && i < gltf_doc_file_count(doc); i++)
        ptr_warn(options->dependencies, "%s", gltf_doc_file(doc, i));
    /* The file's buffers go before the scene's arrays are filled. */
    gltf_doc_free(doc);
    free(im.material_index);
    if (res == PTR_OK)
        res = ptr_import_finish(&im.builder, path, err);
    ptr_builder_free(&im.builder);
    return res;
}
