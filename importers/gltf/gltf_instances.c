/* A node's spheres (gltf_instances.h). */
#include "gltf_instances.h"

#include <stdlib.h>
#include <string.h>

#include "base/cpu.h"
#include "base/threads.h"
#include "gltf_accessors.h"
#include "gltf_materials.h"
#include "gltf_surfaces.h"

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
    gltf_origin_text(o, where, sizeof where);
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
        gltf_mat4_point(world, origin, centre);
        *radius = node->radius;
        return;
    }
    gltf_mat4_point(world, &surface->spheres[4 * k], centre);
    *radius = surface->spheres[4 * k + 3] * scale;
}

/* Checks the accessor of the attribute --color-by names (index from
 * gltf_doc_*_attribute: -2 if it names no accessor) as o's `what`. */
static PtrResult value_accessor(Importer *im, const Origin *o, const char *what, int index,
                                size_t *count, GltfAccessor *a)
{
    if (index == -2) {
        char where[160];
        gltf_origin_text(o, where, sizeof where);
        return ptr_error_set(im->err, PTR_ERR_SCENE_INVALID,
                             "%s: %s: %s attribute '%s' refers to an accessor that does not "
                             "exist", im->path, where, what, im->value_name);
    }
    return gltf_attribute_accessor(im, o, im->value_name, index, 1, 4, QUANTIZED, count, a);
}

/* Element i of a value accessor: the number, or the length of a vector
 * (docs/scenes.md). Returns 0 unless it is finite. */
static int element_value(const GltfAccessor *a, size_t i, double *value)
{
    double v[4], sum = 0;
    gltf_element(a, i, v);
    for (int c = 0; c < a->components; c++)
        sum += v[c] * v[c];
    *value = a->components == 1 ? v[0] : sqrt(sum);
    return isfinite(*value);
}

/* Whether an instance's SCALE is one: each axis's above 0 and finite. */
static int scale_ok(const double scale[3])
{
    for (int k = 0; k < 3; k++)
        if (!(scale[k] > 0) || !isfinite(scale[k]))
            return 0;
    return 1;
}

/* T * R * S of instance i, from the attributes present. */
static int instance_local(const GltfAccessor *t, const GltfAccessor *r, const GltfAccessor *s,
                          size_t i, Mat4 *out)
{
    double translation[3] = { 0, 0, 0 }, rotation[4] = { 0, 0, 0, 1 }, scale[3] = { 1, 1, 1 };
    double v[4];
    if (t) {
        gltf_element(t, i, v);
        memcpy(translation, v, sizeof translation);
    }
    if (r) {
        gltf_element(r, i, v);
        double length = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + v[3] * v[3]);
        if (!(length > 0) || !isfinite(length))
            return 0;
        for (int k = 0; k < 4; k++)
            rotation[k] = v[k] / length; /* quantized rotations are not quite unit */
    }
    if (s) {
        gltf_element(s, i, v);
        if (!scale_ok(v))
            return 0;
        memcpy(scale, v, sizeof scale);
    }
    *out = gltf_trs_matrix(translation, rotation, scale);
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
    const GltfDoc *doc; /* whose pages each block gives back (release_slots) */
    const GltfNode *node;
    const GltfMesh *mesh;
    const SurfaceSpheres *surface;
    size_t surface_count;        /* surface spheres an instance */
    uint32_t *surface_materials; /* theirs */
    const Mat4 *world;
    int world_identity; /* world is the identity (see gltf_mat4_identity_mul) */
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

/* The world of instance i of a run under an identity world whose instances
 * have no rotation, and its largest axis scale (*uneven set if they
 * differ); 0 where instance_local refuses the instance. The entries are
 * those of gltf_mat4_identity_mul(instance_local), without its products:
 * for the quaternion (0, 0, 0, 1), gltf_trs_matrix's rotation terms are
 * products and sums of 0 and 1, so exactly 1 on the diagonal and +0 off it,
 * and the columns are the scale (above 0, times 1) and +0s, then the
 * translation. Adding 0.0, as the identity's product does, turns a -0
 * translation into +0 and changes nothing else. An axis's scale, the length
 * of its column, is then sqrt(s s + 0 + 0): sqrt(s s), once where all three
 * are one. Large clouds' instances are so, and the general product and
 * lengths were a sixth of their import (docs/intersectors.md, "Instances
 * without rotations"). */
static int moved_and_scaled(const NodeRun *run, size_t i, Mat4 *world, double *scale,
                            int *uneven)
{
    double t[4] = { 0, 0, 0, 0 }, s[4] = { 1, 1, 1, 1 };
    if (run->has_t)
        gltf_element(&run->t, i, t);
    if (run->has_s)
        gltf_element(&run->s, i, s);
    if (!scale_ok(s) || !all_finite(t, 3))
        return 0;
    *world = (Mat4){ { s[0], 0.0, 0.0, 0.0, 0.0, s[1], 0.0, 0.0, 0.0, 0.0, s[2], 0.0,
                       t[0] + 0.0, t[1] + 0.0, t[2] + 0.0, 1.0 } };
    *scale = s[0] == s[1] && s[1] == s[2] ? sqrt(s[0] * s[0]) : gltf_axis_scale(world, uneven);
    return 1;
}

/* Instance i of the run, or why it gives no spheres. Always inline, as is
 * instance_spheres: in convert_slots' loop their calls and the stores and
 * loads of the Instance between them were a tenth of an instanced cloud's
 * conversion. (slot_error and gltf_add_node_spheres get copies too, which
 * run once a node.) */
static inline __attribute__((always_inline)) Fault instance_at(const NodeRun *run, size_t i,
                                                               Instance *out)
{
    out->uneven = 0;
    if (run->instanced && run->world_identity && !run->has_r) {
        if (!moved_and_scaled(run, i, &out->world, &out->scale, &out->uneven))
            return TRANSFORM_FAULT;
    } else {
        Mat4 local;
        if (run->instanced &&
            !instance_local(run->has_t ? &run->t : NULL, run->has_r ? &run->r : NULL,
                            run->has_s ? &run->s : NULL, i, &local))
            return TRANSFORM_FAULT;
        /* local is finite (instance_local checks it), as the identity's
         * product without its products needs. */
        out->world = !run->instanced      ? *run->world
                     : run->world_identity ? gltf_mat4_identity_mul(&local)
                                           : gltf_mat4_mul(run->world, &local);
        out->scale = gltf_axis_scale(&out->world, &out->uneven);
    }
    out->has_color = run->has_c;
    if (run->has_c)
        gltf_element(&run->c, i, out->color);
    out->has_value = run->has_v;
    if (run->has_v && !element_value(&run->v, i, &out->value))
        return VALUE_FAULT;
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
    gltf_element(&ps->pos, j, p);
    gltf_mat4_point(&in->world, p, centre);
    if (ps->has_rad)
        gltf_element(&ps->rad, j, r);
    else
        r[0] = ps->radius;
    if (ps->has_val && !element_value(&ps->val, j, &value))
        return VALUE_FAULT;
    const double radius = r[0] * in->scale;
    if (sphere_fault(centre, radius))
        return SPHERE_FAULT;
    if (ps->has_col)
        gltf_element(&ps->col, j, c);
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
static inline __attribute__((always_inline)) Fault
instance_spheres(const NodeRun *run, size_t i, const Instance *in, size_t k, size_t end,
                 size_t *at)
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
            gltf_note_failure(&run->failed, i * run->slots + at);
            break;
        }
        nonuniform |= in.uneven;
        slot += stop - k;
    }
    if (nonuniform && run->scaled)
        atomic_store(&run->nonuniform, 1);
}

/* A node of this many slots or more is converted on all cores, and every
 * node a block at a time (ptr_builder_block_end), the file's pages read
 * given back after each block. */
enum { PARALLEL_PARTS = 1 << 15 };

/* Gives back the file's pages read for slots begin .. end - 1 (see
 * gltf_doc_release): the instances' attributes, or the points' where no
 * other instance reads them again. */
static void release_slots(const NodeRun *run, size_t begin, size_t end)
{
    if (run->instanced) {
        const GltfAccessor *read[] = { run->has_t ? &run->t : NULL, run->has_r ? &run->r : NULL,
                                       run->has_s ? &run->s : NULL, run->has_c ? &run->c : NULL,
                                       run->has_v ? &run->v : NULL };
        for (size_t a = 0; a < sizeof read / sizeof read[0]; a++)
            if (read[a])
                gltf_doc_release(run->doc, read[a], begin / run->slots, end / run->slots);
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
                gltf_doc_release(run->doc, read[a], lo, hi);
    }
}

static PtrResult value_error(Importer *im, const Origin *o)
{
    char where[160];
    gltf_origin_text(o, where, sizeof where);
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
        res = gltf_attribute_accessor(im, o, "TRANSLATION", in->translation, 3, 3, QUANTIZED,
                                      &count, &run->t);
    if (res == PTR_OK && run->has_r)
        res = gltf_attribute_accessor(im, o, "ROTATION", in->rotation, 4, 4, FLOATS_OR_SIGNED,
                                      &count, &run->r);
    if (res == PTR_OK && run->has_s)
        res = gltf_attribute_accessor(im, o, "SCALE", in->scale, 3, 3, QUANTIZED, &count, &run->s);
    if (res == PTR_OK && run->has_c)
        res = gltf_attribute_accessor(im, o, "_COLOR_0", in->color, 3, 4, FLOATS_OR_UNSIGNED,
                                      &count, &run->c);
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
    PtrResult res = gltf_attribute_accessor(im, o, "POSITION", prim->position, 3, 3, QUANTIZED,
                                            &ps->count, &ps->pos);
    if (res == PTR_OK && ps->has_rad)
        res = gltf_attribute_accessor(im, o, "_RADIUS", prim->radius, 1, 1, FLOATS, &ps->count,
                                      &ps->rad);
    if (res == PTR_OK && ps->has_col)
        res = gltf_attribute_accessor(im, o, "COLOR_0", prim->color, 3, 4, FLOATS_OR_UNSIGNED,
                                      &ps->count, &ps->col);
    if (res == PTR_OK && ps->has_val)
        res = value_accessor(im, o, "point", value_index, &ps->count, &ps->val);
    if (res == PTR_OK)
        res = gltf_map_material(im, prim->material, &ps->material);
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
            res = gltf_map_material(im, node->has_radius ? mesh->material
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

/* After a block of the run's slots is converted: gives back its pages,
 * and says whether to go on (no slot failed). */
static int slots_done(void *arg, size_t begin, size_t end)
{
    const NodeRun *run = arg;
    release_slots(run, begin, end);
    return atomic_load(&run->failed) == SIZE_MAX;
}

/* Converts the run's slots, on all cores where there are PARALLEL_PARTS or
 * more, a block at a time (ptr_builder_fill_blocks), and stops after a
 * block where a slot failed. Fails only for memory. */
static PtrResult convert_run(const Importer *im, NodeRun *run)
{
    const size_t slots = run->instances * run->slots;
    const int threads = slots >= PARALLEL_PARTS ? ptr_usable_cpus() : 1;
    if (ptr_builder_fill_blocks(run->builder, run->first, slots, threads, convert_slots,
                                slots_done, run) != PTR_OK)
        return ptr_error_set(im->err, PTR_ERR_NOMEM, "%s: out of memory", im->path);
    return PTR_OK;
}

PtrResult gltf_add_node_spheres(Importer *im, size_t node_index, const GltfNode *node,
                                const Mat4 *world)
{
    GltfMesh mesh;
    gltf_doc_mesh(im->doc, (size_t)node->mesh, &mesh);
    const Origin o = { node_index, label(node->name, "unnamed"), NULL, 0 };
    const Origin instance = { node_index, o.node_name, node->instanced ? "instance" : NULL, 0 };
    NodeRun run = { .builder = &im->builder, .doc = im->doc, .node = node, .mesh = &mesh,
                    .world = world, .world_identity = gltf_mat4_is_identity(world),
                    .instanced = node->instanced, .instances = 1, .slots = 1 };
    atomic_init(&run.failed, SIZE_MAX);
    atomic_init(&run.nonuniform, 0);
    PtrResult res = gltf_surface_spheres(im, &o, (size_t)node->mesh, &run.surface);
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
        gltf_note_skipped(im, &o, &mesh, run.surface->skipped * run.instances);
    Instance first;
    int warned = 0;
    if (res == PTR_OK && instance_at(&run, 0, &first) != NO_FAULT)
        res = slot_error(im, &run, &instance, 0);
    if (res == PTR_OK)
        res = run_mesh(im, &instance, &run, &first, &warned);
    if (res == PTR_OK)
        res = start_run(im, &run);
    if (res == PTR_OK)
        res = convert_run(im, &run);
    if (res == PTR_OK) {
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
