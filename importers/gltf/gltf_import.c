/* glTF nodes to spheres, following docs/scenes.md. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

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

/* T * R * S, as glTF composes a node's TRS properties. */
static Mat4 node_local(const GltfNode *n)
{
    Mat4 r;
    if (n->has_matrix) {
        memcpy(r.m, n->matrix, sizeof r.m);
        return r;
    }
    const double x = n->rotation[0], y = n->rotation[1], z = n->rotation[2],
                 w = n->rotation[3];
    const double rot[9] = {
        1 - 2 * (y * y + z * z), 2 * (x * y + z * w), 2 * (x * z - y * w),
        2 * (x * y - z * w), 1 - 2 * (x * x + z * z), 2 * (y * z + x * w),
        2 * (x * z + y * w), 2 * (y * z - x * w), 1 - 2 * (x * x + y * y),
    };
    for (int c = 0; c < 3; c++) {
        for (int row = 0; row < 3; row++)
            r.m[c * 4 + row] = rot[c * 3 + row] * n->scale[c];
        r.m[c * 4 + 3] = 0.0;
    }
    r.m[12] = n->translation[0];
    r.m[13] = n->translation[1];
    r.m[14] = n->translation[2];
    r.m[15] = 1.0;
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
    uint32_t *material_index; /* glTF material -> scene material, UINT32_MAX unset */
    uint32_t default_material;
    int warned_texture;
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
    if (ptr_scene_add_material(im->scene, &m, slot) != PTR_OK)
        return ptr_error_set(im->err, PTR_ERR_NOMEM, "%s: out of memory", im->path);
    *out = *slot;
    return PTR_OK;
}

static PtrResult add_sphere(Importer *im, size_t node_index, const GltfNode *node,
                            const Mat4 *world)
{
    const char *name = label(node->name, "unnamed");
    GltfMesh mesh;
    gltf_doc_mesh(im->doc, (size_t)node->mesh, &mesh);

    double centre[3], radius;
    double scale[3] = { column_length(world, 0), column_length(world, 1),
                        column_length(world, 2) };
    if (node->has_radius) {
        const double origin[3] = { 0, 0, 0 };
        mat4_point(world, origin, centre);
        radius = node->radius;
    } else {
        if (!mesh.has_bounds)
            return ptr_error_set(im->err, PTR_ERR_SCENE_INVALID,
                                 "%s: node %zu ('%s'): mesh %d has no POSITION min/max bounds",
                                 im->path, node_index, name, node->mesh);
        double local[3], extent = 0.0;
        for (int k = 0; k < 3; k++) {
            local[k] = 0.5 * (mesh.min[k] + mesh.max[k]);
            extent = fmax(extent, mesh.max[k] - mesh.min[k]);
        }
        mat4_point(world, local, centre);
        radius = 0.5 * extent * fmax(scale[0], fmax(scale[1], scale[2]));
        double smin = fmin(scale[0], fmin(scale[1], scale[2]));
        double smax = fmax(scale[0], fmax(scale[1], scale[2]));
        if (smax - smin > 1e-6 * smax)
            ptr_warn(im->warnings,
                     "%s: node '%s' has a non-uniform scale; its sphere takes the largest axis",
                     im->path, name);
    }
    float r = (float)radius;
    if (!(r > 0.0f) || !isfinite(r) || !all_finite(centre, 3))
        return ptr_error_set(im->err, PTR_ERR_SCENE_INVALID,
                             "%s: node %zu ('%s') gives a sphere with a non-finite centre "
                             "or a radius that is not positive and finite",
                             im->path, node_index, name);
    uint32_t material = 0;
    PtrResult res = map_material(im, mesh.material, &material);
    if (res != PTR_OK)
        return res;
    if (ptr_builder_add_sphere(&im->builder, centre, radius, material) != PTR_OK)
        return ptr_error_set(im->err, PTR_ERR_NOMEM, "%s: out of memory", im->path);
    return PTR_OK;
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
    if (!cam.perspective) {
        ptr_warn(im->warnings, "%s: camera '%s' is not perspective and is ignored", im->path,
                 label(cam.name, label(node->name, "unnamed")));
        return PTR_OK;
    }
    const double origin[3] = { 0, 0, 0 };
    double eye[3];
    mat4_point(world, origin, eye);
    double focus = cam.has_focus_distance ? cam.focus_distance : 1.0;
    double aperture = cam.has_aperture ? cam.aperture : 0.0;
    double yfov_deg = cam.yfov * 180.0 / 3.14159265358979323846;
    double fwd_len = column_length(world, 2), up_len = column_length(world, 1);
    if (!all_finite(world->m, 16) || !(fwd_len > 0) || !(up_len > 0) ||
        !(yfov_deg > 0 && yfov_deg < 180) || !(focus > 0) || !isfinite(focus) ||
        !(aperture >= 0) || !isfinite(aperture) || !(cam.aspect_ratio >= 0))
        return ptr_error_set(im->err, PTR_ERR_SCENE_INVALID,
                             "%s: camera '%s' has a degenerate transform or a value out of range",
                             im->path, label(cam.name, label(node->name, "unnamed")));
    double target[3], up[3];
    for (int k = 0; k < 3; k++) {
        /* A glTF camera looks down its local -Z with +Y up. */
        target[k] = eye[k] - world->m[8 + k] / fwd_len * focus;
        up[k] = world->m[4 + k] / up_len;
    }
    const PtrCamera lens = {
        .vfov_deg = (float)yfov_deg, .aperture = (float)aperture,
        .focus_distance = (float)focus, .aspect = (float)cam.aspect_ratio,
    };
    ptr_builder_set_camera(&im->builder, eye, target, up, &lens);
    im->camera_found = 1;
    return PTR_OK;
}

/* Depth-first, pre-order, over the default scene; glTF requires the nodes to
 * form trees, so a node met twice is an error (a cycle or a shared child). */
static PtrResult walk_nodes(Importer *im, const GltfScene *gs)
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
            if (node.mesh >= 0)
                res = add_sphere(im, (size_t)index, &node, &world[index]);
            if (res == PTR_OK && node.camera >= 0)
                res = take_camera(im, &node, &world[index]);
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
    if (gs->sky_invalid || (gs->sky_name && !ptr_sky_parse(gs->sky_name, &scene->sky)) ||
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
    char message[sizeof err->message];
    int unreadable;
    GltfDoc *doc = gltf_doc_load(path, message, sizeof message, &unreadable);
    if (!doc)
        return ptr_error_set(err, unreadable ? PTR_ERR_SCENE_UNREADABLE : PTR_ERR_SCENE_INVALID,
                             "%s", message);

    Importer im = {
        .path = path, .doc = doc, .scene = scene, .warnings = warnings, .err = err,
        .camera_name = options ? options->camera_name : NULL,
        .default_material = UINT32_MAX,
    };
    ptr_builder_init(&im.builder, scene, options ? options->camera : NULL);
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
        if (res == PTR_OK)
            res = walk_nodes(&im, &gs);
    }
    if (res == PTR_OK && im.camera_name && !im.camera_found && !(options && options->camera))
        res = ptr_error_set(err, PTR_ERR_SCENE_INVALID,
                            "%s: no perspective camera named '%s' in the default scene", path,
                            im.camera_name);
    for (size_t i = 0; options && options->dependencies && i < gltf_doc_file_count(doc); i++)
        ptr_warn(options->dependencies, "%s", gltf_doc_file(doc, i));
    if (res == PTR_OK && ptr_builder_finish(&im.builder, PTR_BUILD_DEFAULT) != PTR_OK)
        res = ptr_error_set(err, PTR_ERR_SCENE_INVALID,
                            "%s: a sphere lies too far from the camera for single precision", path);
    ptr_builder_free(&im.builder);
    free(im.material_index);
    gltf_doc_free(doc);
    return res;
}
