/* glTF nodes to spheres, following docs/scenes.md: the default scene's
 * nodes walked, its cameras and extras read. */
#include <stdlib.h>
#include <string.h>

#include "gltf_instances.h"
#include "gltf_surfaces.h"
#include "gltf_transforms.h"

enum { MAX_RESOLUTION = 1 << 16 };

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
    gltf_mat4_point(world, origin, eye);
    double fwd_len = gltf_column_length(world, 2), up_len = gltf_column_length(world, 1);
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
    const PtrBuilderSpheres spheres = b->spheres;
    for (size_t i = 0; i < b->count; i++) {
        double s[4];
        ptr_builder_sphere(spheres, i, s);
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
        PtrResult res = gltf_surface_spheres(im, o, (size_t)node->mesh, &surface);
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
        res = gltf_add_node_spheres(im, index, node, world);
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
            Mat4 local = gltf_node_local(&node);
            world[index] = parent[index] < 0 ? local : gltf_mat4_mul(&world[parent[index]], &local);
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
                 "\"What becomes a sphere\"): %s%s", path, im.skipped, im.skipped == 1 ? "" : "s",
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
