/* The public API's contexts and scenes (include/ptr/ptr.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "api/api_internal.h"
#include "base/cpu.h"
#include "base/threads.h"
#include "base/version.h"
#include "builder.h"
#include "importer.h"
#include "scene/colormap.h"

/* The public codes are the internal ones, number for number. */
#define SAME_CODE(status, result) _Static_assert((int)status == (int)result, #status)
SAME_CODE(PTR_STATUS_OK, PTR_OK);
SAME_CODE(PTR_STATUS_INTERNAL, PTR_ERR_INTERNAL);
SAME_CODE(PTR_STATUS_USAGE, PTR_ERR_USAGE);
SAME_CODE(PTR_STATUS_SCENE_UNREADABLE, PTR_ERR_SCENE_UNREADABLE);
SAME_CODE(PTR_STATUS_SCENE_INVALID, PTR_ERR_SCENE_INVALID);
SAME_CODE(PTR_STATUS_OUTPUT, PTR_ERR_OUTPUT);
SAME_CODE(PTR_STATUS_NOMEM, PTR_ERR_NOMEM);
SAME_CODE(PTR_STATUS_COLOR, PTR_ERR_COLOR);
SAME_CODE(PTR_STATUS_CANCELLED, PTR_ERR_INTERRUPTED);
SAME_CODE(PTR_STATUS_INSTALL, PTR_ERR_INSTALL);
_Static_assert(sizeof ((PtrErrorInfo *)0)->message == sizeof ((PtrError *)0)->message,
               "one message size");

PtrStatus ptr_api_fail(PtrErrorInfo *err, const PtrError *error)
{
    if (err) {
        err->code = (PtrStatus)error->code;
        memcpy(err->message, error->message, sizeof err->message);
    }
    return (PtrStatus)error->code;
}

PtrStatus ptr_api_usage(PtrErrorInfo *err, const char *message)
{
    PtrError e;
    ptr_error_set(&e, PTR_ERR_USAGE, "%s", message);
    return ptr_api_fail(err, &e);
}

PtrResult ptr_api_check_number(const char *name, PtrRenderNumber number, long long value,
                               PtrError *err)
{
    if (value < 0 || !ptr_render_number_ok(number, (uint64_t)value))
        return ptr_error_set(err, PTR_ERR_USAGE, "%s: %lld is not %s", name, value,
                             ptr_render_number_range(number));
    return PTR_OK;
}

const char *ptr_version(void)
{
    return PTR_VERSION;
}

PtrStatus ptr_context_new(const PtrContextOptions *options, PtrContext **out, PtrErrorInfo *err)
{
    const PtrContextOptions none = { 0 };
    const PtrContextOptions *o = options ? options : &none;
    PtrError e;
    PtrCpuLevel cap = PTR_CPU_LEVEL_COUNT - 1;
    if (!out)
        return ptr_api_usage(err, "context: out is NULL");
    if (ptr_api_check_number("threads", PTR_NUMBER_THREADS, o->threads, &e) != PTR_OK)
        return ptr_api_fail(err, &e);
    PtrError problem;
    if (o->cpu_cap && ptr_cpu_parse_level(o->cpu_cap, &cap, &problem) != PTR_OK) {
        ptr_error_set(&e, PTR_ERR_USAGE, "cpu_cap: %s", problem.message);
        return ptr_api_fail(err, &e);
    }
    PtrContext *c = calloc(1, sizeof *c);
    if (!c || (o->weights_dir && !(c->weights_dir = strdup(o->weights_dir)))) {
        free(c);
        ptr_error_set(&e, PTR_ERR_NOMEM, "out of memory");
        return ptr_api_fail(err, &e);
    }
    c->threads = o->threads;
    c->cpu_level = cap < ptr_cpu_level() ? cap : ptr_cpu_level();
    /* The kept threads and the EXR writer's are the process's: both only
     * change how fast work is done, never a result (docs/architecture.md,
     * "State a caller owns"). */
    const int threads = ptr_thread_count(o->threads);
    ptr_threads_keep(threads);
    if (ptr_image_set_threads(threads, &e) != PTR_OK ||
        ptr_image_loader_new(&c->images, &e) != PTR_OK ||
        ptr_color_open(o->ocio_config, &c->color, &e) != PTR_OK) {
        ptr_context_free(c);
        return ptr_api_fail(err, &e);
    }
    *out = c;
    return PTR_STATUS_OK;
}

void ptr_context_free(PtrContext *context)
{
    if (!context)
        return;
    for (size_t q = 0; q < sizeof context->denoisers / sizeof context->denoisers[0]; q++)
        ptr_denoiser_free(context->denoisers[q]);
    if (context->color)
        ptr_color_close(context->color);
    if (context->images)
        ptr_image_loader_free(context->images);
    free(context->weights_dir);
    free(context);
}

PtrResult ptr_api_scene_adopt(PtrScene *scene, const char *name, double import_seconds,
                              PtrSceneHandle **out, PtrError *err)
{
    PtrSceneHandle *h = calloc(1, sizeof *h);
    if (!h || !(h->name = strdup(name))) {
        free(h);
        ptr_scene_free(scene);
        return ptr_error_set(err, PTR_ERR_NOMEM, "%s: out of memory", name);
    }
    h->scene = *scene;
    h->import_seconds = import_seconds;
    *out = h;
    return PTR_OK;
}

/* The public side of ptr_api_scene_adopt. */
static PtrStatus hand_scene(PtrScene *scene, const char *name, double import_seconds,
                            PtrSceneHandle **out, PtrErrorInfo *err)
{
    PtrError e;
    if (ptr_api_scene_adopt(scene, name, import_seconds, out, &e) != PTR_OK)
        return ptr_api_fail(err, &e);
    return PTR_STATUS_OK;
}

PtrResult ptr_api_camera_spec(const PtrCameraDesc *desc, PtrCameraSpec *spec, PtrError *err)
{
    const double *points[] = { desc->lookfrom, desc->lookat, desc->up };
    for (int p = 0; p < 3; p++)
        for (int k = 0; k < 3; k++)
            if (!isfinite(points[p][k]))
                return ptr_error_set(err, PTR_ERR_USAGE,
                                     "camera: lookfrom, lookat and up are finite");
    memcpy(spec->lookfrom, desc->lookfrom, sizeof spec->lookfrom);
    memcpy(spec->lookat, desc->lookat, sizeof spec->lookat);
    memcpy(spec->up, desc->up, sizeof spec->up);
    spec->vfov_deg = desc->vfov_deg;
    spec->ortho_height = desc->ortho_height;
    spec->aperture = desc->aperture;
    spec->focus_distance = desc->focus_distance;
    return PTR_OK;
}

/* The sky text, if any, into scene. */
static PtrResult apply_sky(const char *sky, PtrScene *scene, PtrError *err)
{
    PtrError problem;
    if (sky && ptr_sky_parse(sky, &scene->sky, &problem) != PTR_OK)
        return ptr_error_set(err, PTR_ERR_USAGE, "sky: %s", problem.message);
    return PTR_OK;
}

/* The colormap and range a load asks for, checked: *map NULL for the
 * default, *range NULL for the values' own. */
static PtrResult read_color_options(const PtrLoadOptions *o, const PtrColormap **map,
                                    const double **range, PtrError *err)
{
    const double *r = o->color_range;
    *map = NULL;
    *range = r[0] != 0.0 || r[1] != 0.0 ? r : NULL;
    if (o->color_by && !*o->color_by)
        return ptr_error_set(err, PTR_ERR_USAGE, "color_by: '' is not an attribute name");
    if (!o->color_by && (o->colormap || *range))
        return ptr_error_set(err, PTR_ERR_USAGE, "colormap and color_range need color_by");
    if (o->colormap && !(*map = ptr_colormap_find(o->colormap)))
        return ptr_error_set(err, PTR_ERR_USAGE, "colormap: '%s' is not " PTR_COLORMAP_NAMES,
                             o->colormap);
    if (*range && !ptr_color_range_ok(r))
        return ptr_error_set(err, PTR_ERR_USAGE, "color_range: %g,%g is not MIN,MAX (finite "
                             "numbers, MIN below MAX)", r[0], r[1]);
    return PTR_OK;
}

/* color_by's quantity, if the import read one, onto the colormap (as the
 * command line's --color-by); a colour scheme, which the importer applied,
 * takes no colormap or range (map and range are NULL without color_by). */
static PtrResult apply_color_by(const char *path, const PtrLoadOptions *o,
                                const PtrColormap *map, const double *range, PtrScene *scene,
                                PtrColorMapping *mapping, PtrError *err)
{
    if (!scene->spheres.value)
        return map || range
                   ? ptr_error_set(err, PTR_ERR_USAGE, "%s: color_by %s is a colour scheme, "
                                   "not a quantity: it takes no colormap or color_range",
                                   path, o->color_by)
                   : PTR_OK;
    PtrError problem;
    PtrResult res = ptr_scene_color_by_range(scene, map, range, mapping, &problem);
    if (res != PTR_OK)
        return ptr_error_set(err, res, "%s: color_by: %s", path, problem.message);
    return PTR_OK;
}

PtrStatus ptr_scene_load(PtrContext *context, const char *path, const PtrLoadOptions *options,
                         PtrSceneHandle **out, PtrErrorInfo *err)
{
    const PtrLoadOptions none = { 0 };
    const PtrLoadOptions *o = options ? options : &none;
    PtrError e;
    if (!context || !path || !out)
        return ptr_api_usage(err, "load: context, path and out are needed, not NULL");
    PtrCameraSpec camera;
    if (o->camera && ptr_api_camera_spec(o->camera, &camera, &e) != PTR_OK)
        return ptr_api_fail(err, &e);
    const PtrColormap *map;
    const double *range;
    if (read_color_options(o, &map, &range, &e) != PTR_OK)
        return ptr_api_fail(err, &e);
    PtrImportOptions import = {
        .camera_name = o->camera_name,
        .camera = o->camera ? &camera : NULL,
        .fit_all_objects = o->fit_all_objects,
        .drop_hydrogens = o->drop_hydrogens,
        .structure_assembly = o->assembly,
        .value_attribute = o->color_by,
        .auto_projection = o->orthographic ? PTR_PROJECTION_ORTHOGRAPHIC
                                           : PTR_PROJECTION_PERSPECTIVE,
        .auto_aspect = o->width && o->height ? (double)o->width / o->height : 0,
        .orbit_degrees = o->orbit_degrees,
        .structure_model = o->model,
        .textures = ptr_texture_decoder(context->images),
    };
    PtrError problem;
    if (o->select && ptr_structure_select_parse(o->select, &import.structure_select, &problem) !=
                         PTR_OK) {
        ptr_error_set(&e, PTR_ERR_USAGE, "select: %s", problem.message);
        return ptr_api_fail(err, &e);
    }
    PtrScene scene;
    PtrStrings warnings = { 0 };
    double start = ptr_now_seconds();
    PtrResult res = ptr_import_scene(path, &import, &scene, &warnings, &e);
    double seconds = ptr_now_seconds() - start;
    /* In the command line's order: the sky, then the colours. */
    PtrColorMapping mapping = { 0 };
    if (res == PTR_OK)
        res = apply_sky(o->sky, &scene, &e);
    if (res == PTR_OK)
        res = apply_color_by(path, o, map, range, &scene, &mapping, &e);
    if (res != PTR_OK) {
        ptr_strings_free(&warnings);
        ptr_scene_free(&scene);
        return ptr_api_fail(err, &e);
    }
    PtrStatus status = hand_scene(&scene, path, seconds, out, err);
    if (status != PTR_STATUS_OK) {
        ptr_strings_free(&warnings);
        return status;
    }
    (*out)->warnings = warnings;
    (*out)->color_mapped = mapping.map != NULL;
    (*out)->color_from = mapping.from;
    (*out)->color_to = mapping.to;
    return PTR_STATUS_OK;
}

/* Checks sphere i of the arrays: PTR_ERR_USAGE naming it if it cannot be
 * rendered. */
static PtrResult check_sphere(const PtrSceneArrays *a, size_t i, const double centre[3],
                              PtrError *err)
{
    for (int k = 0; k < 3; k++)
        if (!isfinite(centre[k]))
            return ptr_error_set(err, PTR_ERR_USAGE, "sphere %zu: centre %g %g %g is not finite",
                                 i, centre[0], centre[1], centre[2]);
    if (!(a->radii[i] >= 0.0f) || isinf(a->radii[i]))
        return ptr_error_set(err, PTR_ERR_USAGE, "sphere %zu: radius %g is not >= 0 and finite", i,
                             (double)a->radii[i]);
    /* No table: one grey material, index 0. */
    const size_t materials = a->material_count ? a->material_count : 1;
    if (a->material_indices && a->material_indices[i] >= materials)
        return ptr_error_set(err, PTR_ERR_USAGE, "sphere %zu: material %u, of %zu materials", i,
                             a->material_indices[i], materials);
    for (int k = 0; a->colors && k < 3; k++)
        if (isnan(a->colors[3 * i + k]))
            return ptr_error_set(err, PTR_ERR_USAGE, "sphere %zu: its colour is NaN", i);
    return PTR_OK;
}

/* The materials of the arrays into the scene (one grey diffuse if none). */
static PtrResult add_materials(const PtrSceneArrays *a, PtrScene *scene, PtrError *err)
{
    static const PtrMaterialKind kinds[] = {
        [PTR_MATERIAL_TYPE_DIFFUSE] = PTR_MATERIAL_DIFFUSE,
        [PTR_MATERIAL_TYPE_METAL] = PTR_MATERIAL_METAL,
        [PTR_MATERIAL_TYPE_DIELECTRIC] = PTR_MATERIAL_DIELECTRIC,
        [PTR_MATERIAL_TYPE_EMISSIVE] = PTR_MATERIAL_DIFFUSE,
    };
    const PtrMaterialDesc grey = { .type = PTR_MATERIAL_TYPE_DIFFUSE, .albedo = { .5f, .5f, .5f } };
    const size_t count = a->material_count ? a->material_count : 1;
    for (size_t m = 0; m < count; m++) {
        const PtrMaterialDesc *d = a->material_count ? &a->materials[m] : &grey;
        if ((unsigned)d->type > PTR_MATERIAL_TYPE_EMISSIVE)
            return ptr_error_set(err, PTR_ERR_USAGE, "material %zu: unknown type %d", m,
                                 (int)d->type);
        const PtrMaterial material = {
            .kind = kinds[d->type],
            .albedo = v3(d->albedo[0], d->albedo[1], d->albedo[2]),
            .fuzz = d->fuzz, .ior = d->ior,
            .emission = v3(d->emission[0], d->emission[1], d->emission[2]),
        };
        const char *problem = ptr_material_problem(&material);
        if (problem)
            return ptr_error_set(err, PTR_ERR_USAGE, "material %zu: %s", m, problem);
        uint32_t index;
        PtrResult res = ptr_scene_add_material(scene, &material, &index, err);
        if (res != PTR_OK)
            return res;
    }
    return PTR_OK;
}

/* The spheres of the arrays into the builder. */
static PtrResult add_spheres(const PtrSceneArrays *a, PtrSceneBuilder *builder, PtrError *err)
{
    PtrResult res = ptr_builder_reserve(builder, a->count, err);
    for (size_t i = 0; res == PTR_OK && i < a->count; i++) {
        double centre[3];
        for (int k = 0; k < 3; k++)
            centre[k] = a->centers ? a->centers[3 * i + k] : a->centers_f64[3 * i + k];
        res = check_sphere(a, i, centre, err);
        if (res == PTR_OK)
            res = ptr_builder_add_sphere(builder, centre, a->radii[i],
                                         a->material_indices ? a->material_indices[i] : 0, err);
        if (res == PTR_OK && a->colors) {
            const double rgb[3] = { a->colors[3 * i], a->colors[3 * i + 1], a->colors[3 * i + 2] };
            res = ptr_builder_set_color(builder, rgb, err);
        }
    }
    return res;
}

PtrStatus ptr_scene_from_arrays(PtrContext *context, const PtrSceneArrays *arrays,
                                PtrSceneHandle **out, PtrErrorInfo *err)
{
    (void)context; /* the arrays need nothing of it: every context takes them */
    PtrError e;
    if (!arrays || !out)
        return ptr_api_usage(err, "arrays: arrays and out are needed, not NULL");
    if (!arrays->radii || !arrays->centers == !arrays->centers_f64 ||
        (arrays->material_count && !arrays->materials))
        return ptr_api_usage(err, "arrays: the radii, one of centers and centers_f64, and the "
                                  "materials counted are needed");
    PtrCameraSpec camera;
    if (arrays->camera && ptr_api_camera_spec(arrays->camera, &camera, &e) != PTR_OK)
        return ptr_api_fail(err, &e);
    const PtrImportOptions import = {
        .camera = arrays->camera ? &camera : NULL,
        .auto_projection = arrays->orthographic ? PTR_PROJECTION_ORTHOGRAPHIC
                                                : PTR_PROJECTION_PERSPECTIVE,
    };
    double start = ptr_now_seconds();
    PtrScene scene;
    ptr_scene_init(&scene);
    scene.width = arrays->width;
    scene.height = arrays->height;
    PtrSceneBuilder builder;
    ptr_builder_init(&builder, &scene, &import);
    PtrResult res = apply_sky(arrays->sky, &scene, &e);
    if (res == PTR_OK)
        res = add_materials(arrays, &scene, &e);
    if (res == PTR_OK)
        res = add_spheres(arrays, &builder, &e);
    PtrError problem;
    if (res != PTR_OK)
        ptr_builder_free(&builder);
    else if ((res = ptr_builder_finish(&builder, PTR_BUILD_DEFAULT, &problem)) != PTR_OK)
        ptr_error_set(&e, res, "arrays: %s", problem.message);
    if (res != PTR_OK) {
        ptr_scene_free(&scene);
        return ptr_api_fail(err, &e);
    }
    return hand_scene(&scene, "arrays", ptr_now_seconds() - start, out, err);
}

size_t ptr_scene_sphere_count(const PtrSceneHandle *scene)
{
    return scene ? scene->scene.spheres.count : 0;
}

size_t ptr_scene_warning_count(const PtrSceneHandle *scene)
{
    return scene ? scene->warnings.count : 0;
}

const char *ptr_scene_warning(const PtrSceneHandle *scene, size_t index)
{
    return scene && index < scene->warnings.count ? scene->warnings.lines[index] : NULL;
}

int ptr_scene_color_range(const PtrSceneHandle *scene, double *from, double *to)
{
    if (!scene || !scene->color_mapped)
        return 0;
    if (from)
        *from = scene->color_from;
    if (to)
        *to = scene->color_to;
    return 1;
}

void ptr_scene_handle_free(PtrSceneHandle *scene)
{
    if (!scene)
        return;
    ptr_strings_free(&scene->warnings);
    if (scene->prepared_valid)
        ptr_prepared_free(&scene->prepared);
    ptr_scene_free(&scene->scene);
    free(scene->name);
    free(scene);
}
