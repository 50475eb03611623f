/* The public API (include/ptr/ptr.h) against the command line: the image
 * ptr_scene_render returns equals, float for float, the EXR `ptr` writes for
 * the same scene and options (a glTF, the seed scene with a transparent
 * background, a molecule, a structure coloured by --color-by); a scene from
 * arrays equals the file it came from; a region's pixels placed as a frame
 * of their own save as the command line's EXR of it; and the errors,
 * warnings, cancellation, saving and contexts side by side. */
#include <math.h>
#include <pthread.h>
#include <string.h>

#include "image/image.h"
#include "importer.h"
#include "ptr/ptr.h"
#include "test.h"
#include "test_files.h"

#define SCENE(name) PTR_SOURCE_DIR "/scenes/" name

static PtrContext *context;

/* Renders path through the API with the options, width 96, 6 samples. */
static PtrFrame *render_file(const char *path, const PtrLoadOptions *load,
                             void (*change)(PtrRenderOptions *))
{
    PtrSceneHandle *scene = NULL;
    PtrFrame *frame = NULL;
    PtrErrorInfo err = { 0 };
    CHECK_INT(ptr_scene_load(context, path, load, &scene, &err), PTR_STATUS_OK);
    if (!scene) {
        fprintf(stderr, "%s\n", err.message);
        return NULL;
    }
    PtrRenderOptions options;
    ptr_render_options_default(&options);
    options.width = 96;
    options.samples = 6;
    if (change)
        change(&options);
    CHECK_INT(ptr_scene_render(context, scene, &options, NULL, NULL, &frame, &err), PTR_STATUS_OK);
    if (!frame)
        fprintf(stderr, "%s\n", err.message);
    ptr_scene_handle_free(scene);
    return frame;
}

/* Whether the frame holds exactly the EXR's pixels (and alpha). */
static void check_same_as_file(const PtrFrame *frame, const char *exr)
{
    PtrImage *image;
    PtrError err;
    CHECK_INT(test_image_read(exr, &image, &err), PTR_OK);
    if (!frame)
        return;
    const int w = ptr_frame_width(frame), h = ptr_frame_height(frame);
    CHECK_INT(ptr_image_width(image), w);
    CHECK_INT(ptr_image_height(image), h);
    const size_t pixels = (size_t)w * (size_t)h;
    const int channels = ptr_frame_channels(frame);
    const float *ours = ptr_frame_pixels(frame), *rgb = ptr_image_pixels(image),
                *alpha = ptr_image_alpha(image);
    CHECK_INT(alpha != NULL, channels == 4);
    size_t differ = 0;
    for (size_t p = 0; p < pixels; p++) {
        differ += memcmp(&ours[channels * p], &rgb[3 * p], 3 * sizeof *rgb) != 0;
        differ += channels == 4 && alpha && memcmp(&ours[4 * p + 3], &alpha[p], sizeof *alpha);
    }
    CHECK_INT(differ, 0);
    ptr_image_free(image);
}

static void transparent(PtrRenderOptions *o) { o->transparent = 1; }

static void test_same_as_command_line(void)
{
    struct {
        const char *scene;
        void (*change)(PtrRenderOptions *);
        const char *extra;
    } cases[] = {
        { SCENE("final.gltf"), NULL, NULL },
        { SCENE("seed.gltf"), transparent, "--transparent" },
        { SCENE("1tii.pdb"), NULL, NULL },
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        const char *out = test_path("cli.exr");
        CHECK_INT(test_ptr(cases[i].scene, "-o", out, "--width", "96", "--samples", "6",
                           "--quiet", cases[i].extra, (char *)NULL),
                  0);
        PtrFrame *frame = render_file(cases[i].scene, NULL, cases[i].change);
        check_same_as_file(frame, out);
        ptr_frame_free(frame);
    }
}

/* Seen from the world's origin, the coordinates relative to the camera are
 * the file's own, rounded to float as the arrays hold them. */
static const PtrCameraDesc origin_camera = {
    .lookat = { 0, 0, -1 }, .up = { 0, 1, 0 }, .vfov_deg = 60,
};

static void test_arrays_same_as_file(void)
{
    /* The spheres as the file gives them, in its order. */
    PtrScene scene;
    PtrStrings warnings = { 0 };
    PtrCameraSpec spec = { .lookat = { 0, 0, -1 }, .up = { 0, 1, 0 }, .vfov_deg = 60 };
    const PtrImportOptions import = { .camera = &spec };
    CHECK_INT(ptr_import_scene(SCENE("seed.gltf"), &import, &scene, &warnings, NULL), PTR_OK);
    ptr_strings_free(&warnings);
    const size_t n = scene.spheres.count;
    float *centers = malloc(n * 3 * sizeof *centers), *radii = malloc(n * sizeof *radii);
    uint32_t *materials = malloc(n * sizeof *materials);
    PtrMaterialDesc *table = calloc(scene.material_count, sizeof *table);
    for (size_t i = 0; i < n; i++) {
        const size_t at = ptr_sphere_id(&scene.spheres, i);
        centers[3 * at] = scene.spheres.cx[i];
        centers[3 * at + 1] = scene.spheres.cy[i];
        centers[3 * at + 2] = scene.spheres.cz[i];
        radii[at] = scene.spheres.radius[i];
        materials[at] = ptr_sphere_material(&scene.spheres, i);
    }
    for (size_t m = 0; m < scene.material_count; m++) {
        const PtrMaterial *s = &scene.materials[m];
        table[m] = (PtrMaterialDesc){
            .type = (PtrMaterialType)s->kind, .albedo = { s->albedo.x, s->albedo.y, s->albedo.z },
            .fuzz = s->fuzz, .ior = s->ior,
            .emission = { s->emission.x, s->emission.y, s->emission.z },
        };
    }
    CHECK(scene.origin[0] == 0 && scene.origin[1] == 0 && scene.origin[2] == 0);
    CHECK(!scene.spheres.color);
    const PtrSceneArrays arrays = {
        .count = n, .centers = centers, .radii = radii, .material_indices = materials,
        .materials = table, .material_count = scene.material_count, .camera = &origin_camera,
        .width = scene.width, .height = scene.height, .sky = "gradient",
    };
    ptr_scene_free(&scene);
    PtrSceneHandle *from_arrays = NULL;
    PtrErrorInfo err;
    CHECK_INT(ptr_scene_from_arrays(context, &arrays, &from_arrays, &err), PTR_STATUS_OK);
    CHECK_INT((int)ptr_scene_sphere_count(from_arrays), (int)n);
    PtrRenderOptions options;
    ptr_render_options_default(&options);
    options.width = 96; /* as render_file renders the file */
    options.samples = 6;
    PtrFrame *ours = NULL;
    CHECK_INT(ptr_scene_render(context, from_arrays, &options, NULL, NULL, &ours, &err),
              PTR_STATUS_OK);
    /* The scene's own camera given for one render changes nothing; another
     * changes the image for that render alone. */
    const PtrCameraDesc above = { .lookfrom = { 0, 2, 1 }, .lookat = { 0, 0, -1 },
                                  .up = { 0, 1, 0 }, .vfov_deg = 60 };
    PtrFrame *same = NULL, *other = NULL, *again = NULL;
    options.camera = &origin_camera;
    CHECK_INT(ptr_scene_render(context, from_arrays, &options, NULL, NULL, &same, &err),
              PTR_STATUS_OK);
    options.camera = &above;
    CHECK_INT(ptr_scene_render(context, from_arrays, &options, NULL, NULL, &other, &err),
              PTR_STATUS_OK);
    options.camera = NULL;
    CHECK_INT(ptr_scene_render(context, from_arrays, &options, NULL, NULL, &again, &err),
              PTR_STATUS_OK);
    const size_t bytes = 96 * 96 * 3 * sizeof(float);
    if (ours && same && other && again) {
        CHECK(!memcmp(ptr_frame_pixels(ours), ptr_frame_pixels(same), bytes));
        CHECK(memcmp(ptr_frame_pixels(ours), ptr_frame_pixels(other), bytes) != 0);
        CHECK(!memcmp(ptr_frame_pixels(ours), ptr_frame_pixels(again), bytes));
    }
    ptr_frame_free(same);
    ptr_frame_free(other);
    ptr_frame_free(again);
    const PtrCameraDesc broken = { .lookfrom = { NAN, 0, 0 }, .up = { 0, 1, 0 } };
    options.camera = &broken;
    CHECK_INT(ptr_scene_render(context, from_arrays, &options, NULL, NULL, &same, &err),
              PTR_STATUS_USAGE);
    options.camera = NULL;

    const PtrLoadOptions load = { .camera = &origin_camera };
    PtrFrame *file = render_file(SCENE("seed.gltf"), &load, NULL);
    if (ours && file) {
        CHECK_INT(ptr_frame_width(ours) * ptr_frame_height(ours),
                  ptr_frame_width(file) * ptr_frame_height(file));
        CHECK(!memcmp(ptr_frame_pixels(ours), ptr_frame_pixels(file),
                      (size_t)ptr_frame_width(ours) * ptr_frame_height(ours) * 3 * sizeof(float)));
    }
    ptr_frame_free(ours);
    ptr_frame_free(file);
    ptr_scene_handle_free(from_arrays);
    free(centers);
    free(radii);
    free(materials);
    free(table);
}

static void test_bad_input(void)
{
    PtrErrorInfo err = { 0 };
    PtrSceneHandle *scene = NULL;
    CHECK_INT(ptr_scene_load(context, "/nonexistent/x.gltf", NULL, &scene, &err),
              PTR_STATUS_SCENE_UNREADABLE);
    CHECK(strstr(err.message, "/nonexistent/x.gltf") != NULL);
    CHECK(scene == NULL);
    /* No message wanted: NULL. */
    CHECK_INT(ptr_scene_load(context, "/nonexistent/x.gltf", NULL, &scene, NULL),
              PTR_STATUS_SCENE_UNREADABLE);

    float centers[6] = { 0, 0, 0, 1, 0, 0 }, radii[2] = { 0.5f, 0.5f };
    uint32_t materials[2] = { 0, 3 };
    PtrSceneArrays arrays = { .count = 2, .centers = centers, .radii = radii };
    centers[4] = NAN;
    CHECK_INT(ptr_scene_from_arrays(context, &arrays, &scene, &err), PTR_STATUS_USAGE);
    CHECK(strstr(err.message, "sphere 1") != NULL);
    centers[4] = 0;
    radii[0] = -1;
    CHECK_INT(ptr_scene_from_arrays(context, &arrays, &scene, &err), PTR_STATUS_USAGE);
    CHECK(strstr(err.message, "sphere 0") != NULL);
    radii[0] = 0.5f;
    arrays.material_indices = materials;
    CHECK_INT(ptr_scene_from_arrays(context, &arrays, &scene, &err), PTR_STATUS_USAGE);
    arrays.material_indices = NULL;
    arrays.sky = "purple";
    CHECK_INT(ptr_scene_from_arrays(context, &arrays, &scene, &err), PTR_STATUS_USAGE);
    CHECK(scene == NULL);
    arrays.sky = NULL;
    CHECK_INT(ptr_scene_from_arrays(context, &arrays, &scene, &err), PTR_STATUS_OK);

    PtrRenderOptions options;
    ptr_render_options_default(&options);
    options.width = 8;
    options.integrator = "sideways";
    PtrFrame *frame = NULL;
    CHECK_INT(ptr_scene_render(context, scene, &options, NULL, NULL, &frame, &err),
              PTR_STATUS_USAGE);
    CHECK(strstr(err.message, "integrator") != NULL);
    CHECK(frame == NULL);
    ptr_scene_handle_free(scene);

    PtrContext *bad = NULL;
    const PtrContextOptions level = { .cpu_cap = "avx9000" };
    CHECK_INT(ptr_context_new(&level, &bad, &err), PTR_STATUS_USAGE);
    CHECK(strstr(err.message, "cpu_cap: 'avx9000' is not") != NULL);
    CHECK(bad == NULL);
}

/* Two spheres of arrays, to make scenes of with one thing changed. */
static float two_centers[6] = { 0, 0, -3, 1, 0, -3 }, two_radii[2] = { 0.5f, 0.5f };

static PtrStatus two_spheres(const PtrMaterialDesc *materials, size_t count,
                             const uint32_t *indices, PtrErrorInfo *err)
{
    const PtrSceneArrays arrays = { .count = 2, .centers = two_centers, .radii = two_radii,
                                    .material_indices = indices, .materials = materials,
                                    .material_count = count };
    PtrSceneHandle *scene = NULL;
    const PtrStatus status = ptr_scene_from_arrays(context, &arrays, &scene, err);
    CHECK_INT(scene != NULL, status == PTR_STATUS_OK);
    ptr_scene_handle_free(scene);
    return status;
}

/* The materials the importers refuse are refused, naming the material;
 * index 0 without a table is the grey material. */
static void test_materials_checked(void)
{
    PtrErrorInfo err;
    const uint32_t first[2] = { 0, 0 }, second[2] = { 0, 1 };
    PtrMaterialDesc table[2] = {
        { .type = PTR_MATERIAL_TYPE_DIFFUSE, .albedo = { .5f, .5f, .5f }, .ior = 1.5f },
        { .type = PTR_MATERIAL_TYPE_DIELECTRIC, .albedo = { 1, 1, 1 }, .ior = 1.5f },
    };
    CHECK_INT(two_spheres(table, 2, second, &err), PTR_STATUS_OK);
    CHECK_INT(two_spheres(NULL, 0, first, &err), PTR_STATUS_OK);
    CHECK_INT(two_spheres(NULL, 0, second, &err), PTR_STATUS_USAGE);
    const PtrMaterialDesc zeroed_glass = { .type = PTR_MATERIAL_TYPE_DIELECTRIC };
    PtrMaterialDesc bad[4];
    for (int k = 0; k < 4; k++)
        bad[k] = table[1];
    bad[0].albedo[1] = NAN;
    bad[1].emission[2] = -1;
    bad[2].ior = 0;
    bad[3] = zeroed_glass;
    for (int k = 0; k < 4; k++) {
        const PtrMaterialDesc with_bad[2] = { table[0], bad[k] };
        CHECK_INT(two_spheres(with_bad, 2, second, &err), PTR_STATUS_USAGE);
        CHECK(strstr(err.message, "material 1") != NULL);
    }
}

/* The command line's limits on a render's numbers and threads. */
static void test_limits(void)
{
    PtrErrorInfo err;
    PtrContext *many = NULL;
    const PtrContextOptions threads = { .threads = 1025 };
    CHECK_INT(ptr_context_new(&threads, &many, &err), PTR_STATUS_USAGE);
    CHECK(strstr(err.message, "threads") != NULL);
    CHECK(many == NULL);

    PtrSceneHandle *scene = NULL;
    const PtrSceneArrays arrays = { .count = 2, .centers = two_centers, .radii = two_radii };
    CHECK_INT(ptr_scene_from_arrays(context, &arrays, &scene, &err), PTR_STATUS_OK);
    PtrRenderOptions good;
    ptr_render_options_default(&good);
    good.width = 8;
    good.samples = 1;
    PtrRenderOptions o[14];
    for (int k = 0; k < 14; k++)
        o[k] = good;
    o[0].samples = (1u << 30) + 1;
    o[1].samples = 0;
    o[2].max_depth = 0;
    o[3].min_samples = 1;
    o[4].threads = 1025;
    o[5].width = 70000;
    o[6].noise_threshold = 0.01f;
    o[6].first_sample = 4;
    o[7].noise_threshold = NAN;
    o[8].first_sample = 1u << 30;
    o[9].height = -1;
    o[10].region[2] = 4; /* x1 without y1 */
    o[11].region[0] = 6; /* x0 past x1 */
    o[11].region[2] = 5;
    o[11].region[3] = 4;
    o[12].region[2] = 9; /* outside the 8 wide image */
    o[12].region[3] = 4;
    o[13].time_budget = -1;
    const char *named[14] = { "samples", "samples", "max_depth", "min_samples", "threads",
                              "width", "samples", "noise_threshold", "samples", "height",
                              "region", "region", "region", "time_budget" };
    PtrFrame *frame = NULL;
    for (int k = 0; k < 14; k++) {
        CHECK_INT(ptr_scene_render(context, scene, &o[k], NULL, NULL, &frame, &err),
                  PTR_STATUS_USAGE);
        CHECK(strstr(err.message, named[k]) != NULL);
        CHECK(frame == NULL);
    }
    CHECK_INT(ptr_scene_render(context, scene, &good, NULL, NULL, &frame, &err), PTR_STATUS_OK);
    ptr_frame_free(frame);
    ptr_scene_handle_free(scene);
}

/* A NULL where an object or an out-parameter is needed: usage, no crash;
 * the accessors answer 0 and NULL. */
static void test_null_arguments(void)
{
    PtrErrorInfo err;
    PtrSceneHandle *scene = NULL;
    PtrFrame *frame = NULL;
    PtrRenderOptions options;
    ptr_render_options_default(&options);
    const float pixels[3] = { 0 };
    const PtrSceneArrays arrays = { .count = 2, .centers = two_centers, .radii = two_radii };
    CHECK_INT(ptr_context_new(NULL, NULL, &err), PTR_STATUS_USAGE);
    CHECK_INT(ptr_scene_load(context, NULL, NULL, &scene, &err), PTR_STATUS_USAGE);
    CHECK_INT(ptr_scene_load(context, SCENE("seed.gltf"), NULL, NULL, &err), PTR_STATUS_USAGE);
    CHECK_INT(ptr_scene_from_arrays(context, NULL, &scene, &err), PTR_STATUS_USAGE);
    CHECK_INT(ptr_scene_from_arrays(context, &arrays, NULL, &err), PTR_STATUS_USAGE);
    CHECK_INT(ptr_scene_from_arrays(context, &arrays, &scene, &err), PTR_STATUS_OK);
    CHECK_INT(ptr_scene_render(context, scene, NULL, NULL, NULL, &frame, &err),
              PTR_STATUS_USAGE);
    CHECK_INT(ptr_scene_render(context, NULL, &options, NULL, NULL, &frame, &err),
              PTR_STATUS_USAGE);
    CHECK_INT(ptr_scene_render(context, scene, &options, NULL, NULL, NULL, &err),
              PTR_STATUS_USAGE);
    CHECK_INT(ptr_frame_new(1, 1, 3, NULL, &frame, &err), PTR_STATUS_USAGE);
    CHECK_INT(ptr_frame_new(1, 1, 3, pixels, NULL, &err), PTR_STATUS_USAGE);
    CHECK_INT(ptr_frame_new(1, 1, 3, pixels, &frame, &err), PTR_STATUS_OK);
    CHECK_INT(ptr_frame_save(context, NULL, frame, NULL, &err), PTR_STATUS_USAGE);
    CHECK_INT(ptr_frame_save(context, test_path("never.exr"), NULL, NULL, &err),
              PTR_STATUS_USAGE);
    CHECK(frame != NULL);
    ptr_frame_free(frame);
    ptr_scene_handle_free(scene);
    CHECK_INT(ptr_frame_width(NULL), 0);
    CHECK_INT(ptr_frame_height(NULL), 0);
    CHECK_INT(ptr_frame_channels(NULL), 0);
    CHECK(ptr_frame_pixels(NULL) == NULL && ptr_frame_albedo(NULL) == NULL &&
          ptr_frame_normal(NULL) == NULL);
    CHECK_INT((int)ptr_scene_sphere_count(NULL), 0);
}

/* A camera that is not finite is usage, where the scene is made too. */
static void test_bad_camera(void)
{
    PtrErrorInfo err;
    PtrSceneHandle *scene = NULL;
    const PtrCameraDesc broken = { .lookfrom = { NAN, 0, 0 }, .up = { 0, 1, 0 },
                                   .vfov_deg = 40 };
    const PtrLoadOptions load = { .camera = &broken };
    CHECK_INT(ptr_scene_load(context, SCENE("seed.gltf"), &load, &scene, &err),
              PTR_STATUS_USAGE);
    CHECK(strstr(err.message, "camera") != NULL);
    const PtrSceneArrays arrays = { .count = 2, .centers = two_centers, .radii = two_radii,
                                    .camera = &broken };
    CHECK_INT(ptr_scene_from_arrays(context, &arrays, &scene, &err), PTR_STATUS_USAGE);
    CHECK(strstr(err.message, "camera") != NULL);
    CHECK(scene == NULL);
}

/* The scene's fingerprint a render of scene saves with options. */
static uint64_t saved_hash(PtrSceneHandle *scene, const PtrRenderOptions *options)
{
    PtrFrame *frame = NULL;
    PtrErrorInfo err;
    CHECK_INT(ptr_scene_render(context, scene, options, NULL, NULL, &frame, &err),
              PTR_STATUS_OK);
    const char *exr = test_path("hashed.exr");
    CHECK_INT(ptr_frame_save(context, exr, frame, NULL, &err), PTR_STATUS_OK);
    ptr_frame_free(frame);
    PtrImage *image;
    uint64_t hash = 0;
    if (test_image_read(exr, &image, NULL) != PTR_OK)
        return 0;
    const char *text = ptr_image_attr(image, "ptr:scene_xxh3");
    CHECK(text != NULL);
    if (text)
        hash = strtoull(text, NULL, 16);
    ptr_image_free(image);
    return hash;
}

/* A build that fails between two that succeed leaves the saved hash the
 * first build's, the fresh scene's. */
static void test_hash_after_failed_build(void)
{
    PtrSceneHandle *fresh = NULL, *scene = NULL;
    CHECK_INT(ptr_scene_load(context, SCENE("final.gltf"), NULL, &fresh, NULL), PTR_STATUS_OK);
    CHECK_INT(ptr_scene_load(context, SCENE("final.gltf"), NULL, &scene, NULL), PTR_STATUS_OK);
    PtrRenderOptions options;
    ptr_render_options_default(&options);
    options.width = 16;
    options.samples = 1;
    const uint64_t expected = saved_hash(fresh, &options);
    CHECK(expected != 0);
    CHECK(saved_hash(scene, &options) == expected);
    PtrRenderOptions failing = options;
    failing.kernel = "asm";
    failing.cpu_cap = "none"; /* no assembly there: the build fails */
    PtrFrame *frame = NULL;
    CHECK_INT(ptr_scene_render(context, scene, &failing, NULL, NULL, &frame, NULL),
              PTR_STATUS_USAGE);
    options.kernel = "c";
    CHECK(saved_hash(scene, &options) == expected);
    ptr_scene_handle_free(fresh);
    ptr_scene_handle_free(scene);
}

static int calls;
static int cancel_at_once(void *user, const PtrProgressInfo *progress)
{
    (void)user;
    (void)progress;
    calls++;
    return 1;
}

/* A long render of final.gltf (400 wide, 2^30 samples, or time_budget
 * seconds) with progress: its status, the frame into *frame. */
static PtrStatus render_long(double time_budget, PtrProgressCallback progress, PtrFrame **frame,
                             PtrErrorInfo *err)
{
    PtrSceneHandle *scene = NULL;
    CHECK_INT(ptr_scene_load(context, SCENE("final.gltf"), NULL, &scene, err), PTR_STATUS_OK);
    PtrRenderOptions options;
    ptr_render_options_default(&options);
    options.width = 400;
    options.samples = 1u << 30;
    options.time_budget = time_budget;
    const PtrStatus status = ptr_scene_render(context, scene, &options, progress, NULL, frame,
                                              err);
    ptr_scene_handle_free(scene);
    return status;
}

static void test_cancel(void)
{
    PtrErrorInfo err;
    PtrFrame *frame = NULL;
    CHECK_INT(render_long(0, cancel_at_once, &frame, &err), PTR_STATUS_CANCELLED);
    CHECK(calls > 0);
    CHECK(frame == NULL);
    CHECK(strstr(err.message, "cancelled") != NULL);
}

static void test_save(void)
{
    PtrFrame *frame = render_file(SCENE("seed.gltf"), NULL, transparent);
    const char *exr = test_path("saved.exr"), *png = test_path("saved.png");
    PtrErrorInfo err;
    CHECK_INT(ptr_frame_save(context, exr, frame, NULL, &err), PTR_STATUS_OK);
    check_same_as_file(frame, exr);
    PtrSaveOptions raw = { .view = "Raw" };
    CHECK_INT(ptr_frame_save(context, png, frame, &raw, &err), PTR_STATUS_OK);
    CHECK(access(png, F_OK) == 0);
    raw.view = "no such view";
    CHECK_INT(ptr_frame_save(context, test_path("saved.png"), frame, &raw, &err),
              PTR_STATUS_USAGE);
    CHECK_INT(ptr_frame_save(context, "/nonexistent/dir/x.exr", frame, NULL, &err),
              PTR_STATUS_OUTPUT);

    /* The same pixels as a frame of their own save to the same pixels. */
    PtrFrame *copy = NULL;
    if (frame)
        CHECK_INT(ptr_frame_new(ptr_frame_width(frame), ptr_frame_height(frame), 4,
                                ptr_frame_pixels(frame), &copy, &err),
                  PTR_STATUS_OK);
    const char *copied = test_path("copied.exr");
    if (copy)
        CHECK_INT(ptr_frame_save(context, copied, copy, NULL, &err), PTR_STATUS_OK);
    check_same_as_file(copy, copied);
    check_same_as_file(frame, copied);
    ptr_frame_free(copy);
    CHECK_INT(ptr_frame_new(0, 4, 3, ptr_frame_pixels(frame), &copy, &err), PTR_STATUS_USAGE);
    CHECK_INT(ptr_frame_new(4, 4, 2, ptr_frame_pixels(frame), &copy, &err), PTR_STATUS_USAGE);
    ptr_frame_free(frame);
}

/* The EXR at path, read; NULL (a failed check) if it cannot be. */
static PtrImage *read_exr(const char *path)
{
    PtrImage *image = NULL;
    PtrError err;
    CHECK_INT(test_image_read(path, &image, &err), PTR_OK);
    return image;
}

/* Whether two files hold the same pixels, alpha and noisy colour, and the
 * same values of the attributes named (or both lack one). */
static void check_same_files(const char *a, const char *b, const char *const *attrs)
{
    PtrImage *x = read_exr(a), *y = read_exr(b);
    if (x && y) {
        const PtrImageLayout lx = ptr_image_layout(x), ly = ptr_image_layout(y);
        CHECK(!memcmp(&lx, &ly, sizeof lx));
        const size_t pixels = (size_t)lx.width * (size_t)lx.height;
        CHECK(!memcmp(ptr_image_pixels(x), ptr_image_pixels(y), pixels * 3 * sizeof(float)));
        CHECK_INT(ptr_image_alpha(x) != NULL, ptr_image_alpha(y) != NULL);
        if (ptr_image_alpha(x) && ptr_image_alpha(y))
            CHECK(!memcmp(ptr_image_alpha(x), ptr_image_alpha(y), pixels * sizeof(float)));
        CHECK_INT(ptr_image_noisy(x) != NULL, ptr_image_noisy(y) != NULL);
        if (ptr_image_noisy(x) && ptr_image_noisy(y))
            CHECK(!memcmp(ptr_image_noisy(x), ptr_image_noisy(y), pixels * 3 * sizeof(float)));
        for (size_t k = 0; attrs[k]; k++) {
            const char *u = ptr_image_attr(x, attrs[k]), *v = ptr_image_attr(y, attrs[k]);
            CHECK(u ? v && !strcmp(u, v) : !v);
        }
    }
    ptr_image_free(x);
    ptr_image_free(y);
}

static void region_and_budget(PtrRenderOptions *o)
{
    o->transparent = 1;
    o->region[0] = 10;
    o->region[1] = 5;
    o->region[2] = 70;
    o->region[3] = 40;
    o->time_budget = 600; /* ample: all the samples */
}

static void denoised(PtrRenderOptions *o) { o->denoise = "fast"; }

/* A region, a time budget and denoising: the frame and the file it saves
 * are the command line's, its metadata and noisy layer too. */
static void test_region_budget_denoise_as_command_line(void)
{
    static const char *const attrs[] = {
        "ptr:scene", "ptr:scene_xxh3", "ptr:samples", "ptr:interrupted", "ptr:kernel",
        "ptr:accel", "ptr:spheres", "ptr:denoised", "ptr:view", "ptr:exposure", NULL,
    };
    struct {
        void (*change)(PtrRenderOptions *);
        const char *extra[6];
    } cases[] = {
        { region_and_budget, { "--transparent", "--region", "10,5,70,40", "--time", "600" } },
        { denoised, { "--denoise", "fast" } },
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        const char *cli = test_path("cli.exr"), *ours = test_path("ours.exr");
        const char *const *e = cases[i].extra;
        CHECK_INT(test_ptr(SCENE("seed.gltf"), "-o", cli, "--width", "96", "--samples", "6",
                           "--quiet", e[0], e[1], e[2], e[3], e[4], e[5], (char *)NULL),
                  0);
        PtrFrame *frame = render_file(SCENE("seed.gltf"), NULL, cases[i].change);
        check_same_as_file(frame, cli);
        PtrErrorInfo err;
        if (frame)
            CHECK_INT(ptr_frame_save(context, ours, frame, NULL, &err), PTR_STATUS_OK);
        check_same_files(cli, ours, attrs);
        CHECK_INT((int)ptr_frame_samples(frame), 6);
        ptr_frame_free(frame);
    }
    /* Where the region lies, and the noisy colour kept. */
    PtrFrame *region = render_file(SCENE("seed.gltf"), NULL, region_and_budget);
    int x, y, w, h;
    ptr_frame_placement(region, &x, &y, &w, &h);
    CHECK(ptr_frame_width(region) == 60 && ptr_frame_height(region) == 35);
    CHECK(x == 10 && y == 5 && w == 96 && h == 96); /* the scene is square */
    CHECK(ptr_frame_noisy(region) == NULL);
    ptr_frame_free(region);
    PtrFrame *clean = render_file(SCENE("seed.gltf"), NULL, denoised);
    CHECK(ptr_frame_noisy(clean) != NULL && ptr_frame_albedo(clean) != NULL);
    ptr_frame_placement(clean, &x, &y, &w, &h);
    CHECK(x == 0 && y == 0 && w == ptr_frame_width(clean) && h == ptr_frame_height(clean));
    ptr_frame_free(clean);
    ptr_frame_placement(NULL, &x, NULL, NULL, &h);
    CHECK(x == 0 && h == 0);
    CHECK(ptr_frame_noisy(NULL) == NULL && ptr_frame_samples(NULL) == 0);
}

#define FIXTURE(name) PTR_SOURCE_DIR "/tests/fixtures/" name

/* --color-by, --colormap and --color-range as load options: the command
 * line's pixels, a structure's colour scheme and a quantity mapped alike. */
static void test_color_by_as_command_line(void)
{
    struct {
        PtrLoadOptions load;
        const char *extra[6];
    } cases[] = {
        { { .color_by = "chain" }, { "--color-by", "chain" } },
        { { .color_by = "bfactor" }, { "--color-by", "bfactor" } },
        { { .color_by = "bfactor", .colormap = "magma", .color_range = { 10, 60 } },
          { "--color-by", "bfactor", "--colormap", "magma", "--color-range", "10,60" } },
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        const char *out = test_path("cli.exr");
        const char *const *e = cases[i].extra;
        CHECK_INT(test_ptr(FIXTURE("structures/1tii.cif"), "-o", out, "--width", "96",
                           "--samples", "6", "--quiet", e[0], e[1], e[2], e[3], e[4], e[5],
                           (char *)NULL),
                  0);
        PtrFrame *frame = render_file(FIXTURE("structures/1tii.cif"), &cases[i].load, NULL);
        check_same_as_file(frame, out);
        ptr_frame_free(frame);
    }
    /* The range mapped: the one given, else the values' own; none for a
     * colour scheme or without color_by. */
    PtrSceneHandle *scene = NULL;
    double from = 0, to = 0;
    CHECK_INT(ptr_scene_load(context, FIXTURE("structures/1tii.cif"), &cases[2].load, &scene,
                             NULL),
              PTR_STATUS_OK);
    CHECK(ptr_scene_color_range(scene, &from, &to) == 1 && from == 10 && to == 60);
    ptr_scene_handle_free(scene);
    CHECK_INT(ptr_scene_load(context, FIXTURE("structures/1tii.cif"), &cases[1].load, &scene,
                             NULL),
              PTR_STATUS_OK);
    CHECK(ptr_scene_color_range(scene, &from, &to) == 1 && from > 0 && to > from);
    ptr_scene_handle_free(scene);
    CHECK_INT(ptr_scene_load(context, FIXTURE("structures/1tii.cif"), &cases[0].load, &scene,
                             NULL),
              PTR_STATUS_OK);
    CHECK(ptr_scene_color_range(scene, NULL, NULL) == 0);
    ptr_scene_handle_free(scene);
    CHECK(ptr_scene_color_range(NULL, &from, &to) == 0);

    const struct {
        PtrLoadOptions load;
        PtrStatus status;
    } bad[] = {
        { { .colormap = "magma" }, PTR_STATUS_USAGE },
        { { .color_range = { 0, 1 } }, PTR_STATUS_USAGE },
        { { .color_by = "bfactor", .colormap = "jet" }, PTR_STATUS_USAGE },
        { { .color_by = "bfactor", .color_range = { 2, 1 } }, PTR_STATUS_USAGE },
        { { .color_by = "bfactor", .color_range = { 0, INFINITY } }, PTR_STATUS_USAGE },
        { { .color_by = "chain", .colormap = "magma" }, PTR_STATUS_USAGE },
        { { .color_by = "chain", .color_range = { 0, 1 } }, PTR_STATUS_USAGE },
        { { .color_by = "temperature" }, PTR_STATUS_SCENE_INVALID },
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        PtrErrorInfo err = { 0 };
        scene = NULL;
        CHECK_INT(ptr_scene_load(context, FIXTURE("structures/1tii.cif"), &bad[i].load, &scene,
                                 &err),
                  bad[i].status);
        CHECK(scene == NULL && err.code == bad[i].status && err.message[0]);
    }
}

/* The import's warnings stay with the scene, in the command line's words. */
static void test_warnings(void)
{
    PtrSceneHandle *scene = NULL;
    CHECK_INT(ptr_scene_load(context, FIXTURE("orthographic.gltf"), NULL, &scene, NULL),
              PTR_STATUS_OK);
    CHECK_INT((int)ptr_scene_warning_count(scene), 2);
    const char *first = ptr_scene_warning(scene, 0), *second = ptr_scene_warning(scene, 1);
    CHECK(first && strstr(first, "orthographic.gltf: camera 'Ortho' is orthographic"));
    CHECK(second && strstr(second, "does not clip at zfar"));
    CHECK(ptr_scene_warning(scene, 2) == NULL);
    ptr_scene_handle_free(scene);
    CHECK_INT(ptr_scene_load(context, SCENE("seed.gltf"), NULL, &scene, NULL), PTR_STATUS_OK);
    CHECK_INT((int)ptr_scene_warning_count(scene), 0);
    ptr_scene_handle_free(scene);
    CHECK_INT((int)ptr_scene_warning_count(NULL), 0);
    CHECK(ptr_scene_warning(NULL, 0) == NULL);
}

/* A region's pixels as a frame of their own, placed where the region lies,
 * save as the command line's EXR of --region: the same windows and pixels. */
static void test_placement(void)
{
    const char *cli = test_path("cli.exr"), *ours = test_path("placed.exr");
    CHECK_INT(test_ptr(SCENE("seed.gltf"), "-o", cli, "--width", "96", "--samples", "6",
                       "--quiet", "--transparent", "--region", "10,5,70,40", (char *)NULL),
              0);
    PtrFrame *region = render_file(SCENE("seed.gltf"), NULL, region_and_budget);
    PtrFrame *copy = NULL;
    PtrErrorInfo err;
    if (region)
        CHECK_INT(ptr_frame_new(ptr_frame_width(region), ptr_frame_height(region), 4,
                                ptr_frame_pixels(region), &copy, &err),
                  PTR_STATUS_OK);
    ptr_frame_free(region);
    if (!copy)
        return;
    const int bad[][4] = {
        { -1, 0, 96, 96 }, { 0, -1, 96, 96 }, { 37, 5, 96, 96 }, { 10, 62, 96, 96 },
        { 10, 5, 65537, 96 }, { 0, 0, 59, 35 }, { 2147483647, 0, 96, 96 },
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++)
        CHECK_INT(ptr_frame_set_placement(copy, bad[i][0], bad[i][1], bad[i][2], bad[i][3],
                                          &err),
                  PTR_STATUS_USAGE);
    CHECK_INT(ptr_frame_set_placement(NULL, 0, 0, 60, 35, &err), PTR_STATUS_USAGE);
    int x, y, w, h;
    ptr_frame_placement(copy, &x, &y, &w, &h);
    CHECK(x == 0 && y == 0 && w == 60 && h == 35); /* a refused placement changes nothing */
    CHECK_INT(ptr_frame_set_placement(copy, 10, 5, 96, 96, &err), PTR_STATUS_OK);
    ptr_frame_placement(copy, &x, &y, &w, &h);
    CHECK(x == 10 && y == 5 && w == 96 && h == 96);
    CHECK_INT(ptr_frame_save(context, ours, copy, NULL, &err), PTR_STATUS_OK);
    static const char *const none[] = { NULL };
    check_same_files(cli, ours, none);
    ptr_frame_free(copy);
}

static char caller_quality[16];
static void denoised_by_caller(PtrRenderOptions *o)
{
    strcpy(caller_quality, "fast");
    o->denoise = caller_quality;
}

/* A frame keeps nothing of the options it was rendered with: the caller's
 * string, changed before the save, is not what the file names. */
static void test_frame_keeps_no_option_string(void)
{
    PtrFrame *frame = render_file(SCENE("seed.gltf"), NULL, denoised_by_caller);
    strcpy(caller_quality, "changed");
    const char *path = test_path("quality.exr");
    PtrErrorInfo err;
    if (frame)
        CHECK_INT(ptr_frame_save(context, path, frame, NULL, &err), PTR_STATUS_OK);
    PtrImage *image = read_exr(path);
    const char *quality = image ? ptr_image_attr(image, "ptr:denoised") : NULL;
    CHECK(quality && !strcmp(quality, "fast"));
    ptr_image_free(image);
    ptr_frame_free(frame);
}

/* A time budget that runs out: the samples done, fewer than asked. */
static void test_time_budget(void)
{
    PtrErrorInfo err;
    PtrFrame *frame = NULL;
    CHECK_INT(render_long(0.2, NULL, &frame, &err), PTR_STATUS_OK);
    CHECK(ptr_frame_samples(frame) >= 1 && ptr_frame_samples(frame) < 1u << 30);
    ptr_frame_free(frame);
}

/* The save options as the command line's: the same file for the same
 * depth, exposure, view and baking; values out of range refused. */
static void test_save_options(void)
{
    const char *cli = test_path("cli_baked.exr"), *ours = test_path("ours_baked.exr");
    CHECK_INT(test_ptr(SCENE("final.gltf"), "-o", cli, "--width", "96", "--samples", "6",
                       "--quiet", "--depth", "half", "--exposure", "1.5", "--view", "Raw",
                       "--bake-view", (char *)NULL),
              0);
    PtrFrame *frame = render_file(SCENE("final.gltf"), NULL, NULL);
    PtrSaveOptions save = { .depth = "half", .exposure = 1.5f, .view = "Raw", .bake_view = 1 };
    PtrErrorInfo err;
    CHECK_INT(ptr_frame_save(context, ours, frame, &save, &err), PTR_STATUS_OK);
    static const char *const attrs[] = { "ptr:view", "ptr:exposure", "ptr:colorspace", NULL };
    check_same_files(cli, ours, attrs);
    PtrSaveOptions bad[4] = { save, save, save, save };
    bad[0].depth = "12";
    bad[1].exposure = 65;
    bad[2].exposure = NAN;
    bad[3].look = "no such look";
    const char *named[4] = { "depth", "exposure", "exposure", "no such look" };
    for (int k = 0; k < 4; k++) {
        CHECK_INT(ptr_frame_save(context, ours, frame, &bad[k], &err), PTR_STATUS_USAGE);
        CHECK(strstr(err.message, named[k]) != NULL);
    }
    save.depth = "16"; /* EXR stores half or float */
    CHECK_INT(ptr_frame_save(context, ours, frame, &save, &err), PTR_STATUS_USAGE);
    const PtrSaveOptions png16 = { .depth = "16", .dither = 1 };
    CHECK_INT(ptr_frame_save(context, test_path("deep.png"), frame, &png16, &err),
              PTR_STATUS_OK);
    ptr_frame_free(frame);
}

/* Two contexts, each with its own CPU level and threads, rendering at once
 * on two threads: each gets the image it gets alone. */
typedef struct Job {
    const char *cap;
    PtrFrame *frame;
} Job;

static void *render_job(void *arg)
{
    Job *job = arg;
    const PtrContextOptions options = { .threads = 1, .cpu_cap = job->cap };
    PtrContext *own = NULL;
    PtrSceneHandle *scene = NULL;
    PtrRenderOptions render;
    ptr_render_options_default(&render);
    render.width = 64;
    render.samples = 4;
    if (ptr_context_new(&options, &own, NULL) == PTR_STATUS_OK &&
        ptr_scene_load(own, SCENE("seed.gltf"), NULL, &scene, NULL) == PTR_STATUS_OK)
        ptr_scene_render(own, scene, &render, NULL, NULL, &job->frame, NULL);
    ptr_scene_handle_free(scene);
    ptr_context_free(own);
    return NULL;
}

static void test_two_contexts(void)
{
    Job jobs[2] = { { "none", NULL }, { NULL, NULL } };
    pthread_t threads[2];
    for (int i = 0; i < 2; i++)
        CHECK_INT(pthread_create(&threads[i], NULL, render_job, &jobs[i]), 0);
    for (int i = 0; i < 2; i++)
        pthread_join(threads[i], NULL);
    CHECK(jobs[0].frame && jobs[1].frame);
    if (jobs[0].frame && jobs[1].frame)
        CHECK(!memcmp(ptr_frame_pixels(jobs[0].frame), ptr_frame_pixels(jobs[1].frame),
                      64 * 64 * 3 * sizeof(float)));
    Job alone = { "none", NULL };
    render_job(&alone);
    if (alone.frame && jobs[0].frame)
        CHECK(!memcmp(ptr_frame_pixels(alone.frame), ptr_frame_pixels(jobs[0].frame),
                      64 * 64 * 3 * sizeof(float)));
    for (int i = 0; i < 2; i++)
        ptr_frame_free(jobs[i].frame);
    ptr_frame_free(alone.frame);
}

/* Two threads saving one path at once, many times: every save succeeds
 * (each write has its own temporary file) and the file holds the pixels. */
typedef struct SaveJob {
    PtrContext *context;
    const PtrFrame *frame;
    const char *path;
    int failed;
} SaveJob;

static void *save_job(void *arg)
{
    SaveJob *job = arg;
    for (int k = 0; k < 40; k++)
        job->failed += ptr_frame_save(job->context, job->path, job->frame, NULL, NULL) !=
                       PTR_STATUS_OK;
    return NULL;
}

static void test_saves_at_once(void)
{
    enum { SIDE = 64 };
    static float pixels[SIDE * SIDE * 3];
    for (size_t p = 0; p < sizeof pixels / sizeof pixels[0]; p++)
        pixels[p] = (float)(p % 97) / 97.0f;
    PtrFrame *frame = NULL;
    CHECK_INT(ptr_frame_new(SIDE, SIDE, 3, pixels, &frame, NULL), PTR_STATUS_OK);
    PtrContext *other = NULL;
    CHECK_INT(ptr_context_new(NULL, &other, NULL), PTR_STATUS_OK);
    const char *path = test_path("shared.exr");
    SaveJob jobs[2] = { { context, frame, path, 0 }, { other, frame, path, 0 } };
    pthread_t threads[2];
    for (int i = 0; i < 2; i++)
        CHECK_INT(pthread_create(&threads[i], NULL, save_job, &jobs[i]), 0);
    for (int i = 0; i < 2; i++)
        pthread_join(threads[i], NULL);
    CHECK_INT(jobs[0].failed + jobs[1].failed, 0);
    check_same_as_file(frame, path);
    ptr_frame_free(frame);
    ptr_context_free(other);
}

int main(void)
{
    if (!test_dir_create("api"))
        return 1;
    PtrErrorInfo err;
    if (ptr_context_new(NULL, &context, &err) != PTR_STATUS_OK) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    static const TestCase cases[] = {
        TEST_CASE(test_same_as_command_line), TEST_CASE(test_arrays_same_as_file),
        TEST_CASE(test_bad_input), TEST_CASE(test_cancel), TEST_CASE(test_save),
        TEST_CASE(test_two_contexts), TEST_CASE(test_materials_checked),
        TEST_CASE(test_limits), TEST_CASE(test_null_arguments), TEST_CASE(test_bad_camera),
        TEST_CASE(test_hash_after_failed_build), TEST_CASE(test_saves_at_once),
        TEST_CASE(test_region_budget_denoise_as_command_line),
        TEST_CASE(test_frame_keeps_no_option_string), TEST_CASE(test_time_budget),
        TEST_CASE(test_save_options), TEST_CASE(test_color_by_as_command_line),
        TEST_CASE(test_warnings), TEST_CASE(test_placement),
    };
    test_run(cases, sizeof cases / sizeof cases[0]);
    ptr_context_free(context);
    test_dir_remove();
    return test_report();
}
