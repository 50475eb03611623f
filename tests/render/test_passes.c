/* The albedo and normal passes (path.h, PtrPathPass): closed forms on a
 * sphere seen head-on (a diffuse sphere's own albedo and its normal towards
 * the camera, the sky clamped where rays miss, a mirror showing what it
 * reflects, tinted by its albedo, a fuzzy metal its own), and the same sums
 * bit for bit whatever the thread count or the regions a render is split
 * into. test_bundles holds the integrators and sample ranges to each
 * other with passes too. Through the command line: the EXR layers, merges
 * of regions and of sample ranges, and the refusals. */
#include "base/cpu.h"
#include "builder.h"
#include "image/image.h"
#include "render/render.h"
#include "test.h"
#include "test_files.h"

#define SEED_SCENE PTR_SOURCE_DIR "/scenes/seed.gltf"

enum { SIZE = 33, PIXELS = SIZE * SIZE, CENTRE = SIZE / 2 * SIZE + SIZE / 2, SAMPLES = 16 };

static const PtrVec3 sky = { 0.3f, 2.0f, 0.5f }, behind_albedo = { 0.2f, 0.7f, 0.4f };

/* A sphere of radius 1 at the origin of material m, seen from (0, 0, 5)
 * through a pinhole, under a constant sky; behind the camera, a diffuse
 * sphere of behind_albedo, which a mirror shows at the image's centre. */
static PtrScene make_scene(PtrMaterial m)
{
    PtrScene scene;
    ptr_scene_init(&scene);
    uint32_t front, back;
    const PtrMaterial diffuse = { .kind = PTR_MATERIAL_DIFFUSE, .albedo = behind_albedo };
    CHECK_INT(ptr_scene_add_material(&scene, &m, &front, NULL), PTR_OK);
    CHECK_INT(ptr_scene_add_material(&scene, &diffuse, &back, NULL), PTR_OK);
    PtrSceneBuilder b;
    ptr_builder_init(&b, &scene, NULL);
    const double centre[3] = { 0, 0, 0 }, behind[3] = { 0, 0, 20 }, eye[3] = { 0, 0, 5 },
                 up[3] = { 0, 1, 0 };
    CHECK_INT(ptr_builder_add_sphere(&b, centre, 1.0, front, NULL), PTR_OK);
    CHECK_INT(ptr_builder_add_sphere(&b, behind, 5.0, back, NULL), PTR_OK);
    const PtrCamera lens = { .vfov_deg = 40.0f, .focus_distance = 5.0f };
    ptr_builder_set_camera(&b, eye, centre, up, &lens);
    CHECK_INT(ptr_builder_finish(&b, PTR_BUILD_DEFAULT, NULL), PTR_OK);
    scene.sky = (PtrSky){ PTR_SKY_CONSTANT, sky };
    return scene;
}

static PtrRenderSettings settings(void)
{
    return (PtrRenderSettings){ .width = SIZE, .height = SIZE, .seed = 9, .max_depth = 8,
                                .threads = 2, .passes = 1 };
}

/* The film of samples [0, SAMPLES) of the settings' region. */
static double *render_film(const PtrScene *scene, const PtrRenderSettings *s)
{
    PtrIsectTable isect;
    CHECK_INT(ptr_isect_init(&isect, PTR_KERNEL_AUTO, ptr_cpu_level(), scene->spheres.count,
                             NULL),
              PTR_OK);
    const PtrAccel accel = ptr_accel_brute(&isect, scene);
    PtrRegion r = ptr_render_region(s);
    size_t pixels = (size_t)(r.x1 - r.x0) * (size_t)(r.y1 - r.y0);
    double *acc = ptr_accum_alloc(pixels, PTR_ACCUM_STRIDE_PASSES);
    PtrError err = { 0 };
    CHECK_INT(ptr_render_samples(scene, &accel, s, 0, SAMPLES, acc, NULL, NULL, NULL, &err),
              PTR_OK);
    return acc;
}

/* The resolved passes of the whole image of scene. */
static void render_passes(const PtrScene *scene, float *albedo, float *normal)
{
    PtrRenderSettings s = settings();
    double *acc = render_film(scene, &s);
    ptr_accum_resolve_passes(acc, PIXELS, albedo, normal);
    ptr_accum_free(acc, PIXELS, PTR_ACCUM_STRIDE_PASSES);
}

static void check_v3(const float *got, PtrVec3 want, float tol)
{
    CHECK_NEAR(got[0], want.x, tol);
    CHECK_NEAR(got[1], want.y, tol);
    CHECK_NEAR(got[2], want.z, tol);
}

/* A diffuse sphere covering the centre pixel gives it its albedo, exactly
 * (the mean of equal floats), and its normal towards the camera; a corner
 * sees the sky, clamped to [0, 1], and no normal. */
static void test_diffuse(void)
{
    const PtrVec3 a = { 0.6f, 0.3f, 0.2f };
    PtrScene scene = make_scene((PtrMaterial){ .kind = PTR_MATERIAL_DIFFUSE, .albedo = a });
    static float albedo[PIXELS * 3], normal[PIXELS * 3];
    render_passes(&scene, albedo, normal);
    check_v3(&albedo[3 * CENTRE], a, 0.0f);
    check_v3(&normal[3 * CENTRE], v3(0.0f, 0.0f, 1.0f), 1e-3f);
    check_v3(&albedo[0], v3(0.3f, 1.0f, 0.5f), 0.0f);
    check_v3(&normal[0], v3_splat(0.0f), 0.0f);
    ptr_scene_free(&scene);
}

/* A mirror seen head-on shows the sphere behind the camera: its albedo
 * tinted by the mirror's, its normal facing the mirror. */
static void test_mirror(void)
{
    const PtrVec3 tint = v3_splat(0.5f);
    PtrScene scene = make_scene((PtrMaterial){ .kind = PTR_MATERIAL_METAL, .albedo = tint });
    static float albedo[PIXELS * 3], normal[PIXELS * 3];
    render_passes(&scene, albedo, normal);
    check_v3(&albedo[3 * CENTRE], v3_mul(tint, behind_albedo), 1e-7f);
    /* The convex mirror spreads the centre pixel's rays over a few degrees
     * of the sphere behind: its normals there average to within 0.05. */
    check_v3(&normal[3 * CENTRE], v3(0.0f, 0.0f, -1.0f), 0.05f);
    ptr_scene_free(&scene);
}

/* Metal with fuzz is no mirror: the passes record its own surface. */
static void test_fuzzy_metal(void)
{
    const PtrVec3 a = { 0.9f, 0.6f, 0.3f };
    PtrScene scene =
        make_scene((PtrMaterial){ .kind = PTR_MATERIAL_METAL, .albedo = a, .fuzz = 0.3f });
    static float albedo[PIXELS * 3], normal[PIXELS * 3];
    render_passes(&scene, albedo, normal);
    check_v3(&albedo[3 * CENTRE], a, 0.0f);
    check_v3(&normal[3 * CENTRE], v3(0.0f, 0.0f, 1.0f), 1e-3f);
    ptr_scene_free(&scene);
}

/* Glass seen through: two spheres of glass (in and out of this one, then
 * the sphere behind) leave the sky or the sphere behind, never the glass's
 * own normal at the centre, where every path goes straight through or
 * reflects; the glass's albedo tints both. The sums are the same bit for
 * bit on one thread and two, and when the image renders as four regions. */
static void test_threads_and_regions(void)
{
    PtrScene scene = make_scene((PtrMaterial){ .kind = PTR_MATERIAL_DIELECTRIC,
                                               .albedo = v3(0.9f, 1.0f, 0.9f), .ior = 1.5f });
    PtrRenderSettings s = settings();
    double *whole = render_film(&scene, &s);
    s.threads = 1;
    double *one = render_film(&scene, &s);
    CHECK_INT(memcmp(whole, one, PIXELS * PTR_ACCUM_STRIDE_PASSES * sizeof(double)), 0);
    ptr_accum_free(one, PIXELS, PTR_ACCUM_STRIDE_PASSES);
    const PtrRegion regions[4] = { { 0, 0, 20, 11 }, { 20, 0, SIZE, 11 }, { 0, 11, 7, SIZE },
                                   { 7, 11, SIZE, SIZE } };
    size_t differ = 0;
    for (int i = 0; i < 4; i++) {
        s.region = regions[i];
        double *part = render_film(&scene, &s);
        const PtrRegion *r = &regions[i];
        size_t p = 0;
        for (int y = r->y0; y < r->y1; y++)
            for (int x = r->x0; x < r->x1; x++, p++)
                differ += memcmp(&whole[((size_t)y * SIZE + x) * PTR_ACCUM_STRIDE_PASSES],
                                 &part[p * PTR_ACCUM_STRIDE_PASSES],
                                 PTR_ACCUM_STRIDE_PASSES * sizeof(double)) != 0;
        ptr_accum_free(part, p, PTR_ACCUM_STRIDE_PASSES);
    }
    CHECK_INT(differ, 0);
    float normal_z = (float)(whole[CENTRE * PTR_ACCUM_STRIDE_PASSES + PTR_ACCUM_NORMAL + 2] /
                             SAMPLES);
    CHECK(normal_z < 0.5f); /* never the glass's own normal, (0, 0, 1) */
    ptr_accum_free(whole, PIXELS, PTR_ACCUM_STRIDE_PASSES);
    ptr_scene_free(&scene);
}

/* seed.gltf at 48 x 48 with passes into name, with up to three options
 * more (the first NULL ends them); NULL if ptr fails. */
static PtrImage *render_cli(const char *name, const char *a, const char *b, const char *c)
{
    const char *out = test_path(name);
    if (test_ptr(SEED_SCENE, "-o", out, "--width", "48", "--samples", "8", "--seed", "7",
                 "--passes", "albedo,normal", "--quiet", a, b, c, NULL) != 0)
        return NULL;
    PtrError err;
    PtrImage *image = NULL;
    CHECK_INT(test_image_read(out, &image, &err), PTR_OK);
    return image;
}

/* The largest difference between two images' layers of three floats a
 * pixel (colour, albedo or normal as get gives them), or INFINITY if the
 * sizes differ or a layer is missing. */
static float layer_difference(const PtrImage *a, const PtrImage *b,
                              const float *(*get)(const PtrImage *))
{
    size_t n = (size_t)ptr_image_width(a) * (size_t)ptr_image_height(a) * 3;
    if (ptr_image_width(a) != ptr_image_width(b) || ptr_image_height(a) != ptr_image_height(b) ||
        !get(a) || !get(b))
        return INFINITY;
    float most = 0.0f;
    for (size_t i = 0; i < n; i++)
        most = fmaxf(most, fabsf(get(a)[i] - get(b)[i]));
    return most;
}

/* Regions merged give the whole render's passes bit for bit; sample ranges
 * merged, to the rounding of their means. */
static void test_merges(void)
{
    PtrImage *whole = render_cli("whole.exr", NULL, NULL, NULL);
    CHECK(whole && ptr_image_albedo(whole) && ptr_image_normal(whole));
    PtrImage *top = render_cli("top.exr", "--region", "0,0,48,20", NULL);
    PtrImage *bottom = render_cli("bottom.exr", "--region", "0,20,48,48", NULL);
    PtrImage *early = render_cli("early.exr", "--sample-range", "0:3", NULL);
    PtrImage *late = render_cli("late.exr", "--sample-range", "3:8", NULL);
    CHECK_INT(test_ptr("merge", test_path("top.exr"), test_path("bottom.exr"), "-o",
                       test_path("regions.exr"), "--quiet", NULL),
              0);
    CHECK_INT(test_ptr("merge", test_path("early.exr"), test_path("late.exr"), "-o",
                       test_path("ranges.exr"), "--quiet", NULL),
              0);
    PtrImage *regions = NULL, *ranges = NULL;
    PtrError err;
    CHECK_INT(test_image_read(test_path("regions.exr"), &regions, &err), PTR_OK);
    CHECK_INT(test_image_read(test_path("ranges.exr"), &ranges, &err), PTR_OK);
    if (whole && regions && ranges) {
        CHECK_FLOAT_EQ(layer_difference(whole, regions, ptr_image_pixels), 0.0f);
        CHECK_FLOAT_EQ(layer_difference(whole, regions, ptr_image_albedo), 0.0f);
        CHECK_FLOAT_EQ(layer_difference(whole, regions, ptr_image_normal), 0.0f);
        CHECK(layer_difference(whole, ranges, ptr_image_albedo) < 1e-6f);
        CHECK(layer_difference(whole, ranges, ptr_image_normal) < 1e-6f);
    }
    ptr_image_free(whole);
    ptr_image_free(top);
    ptr_image_free(bottom);
    ptr_image_free(early);
    ptr_image_free(late);
    ptr_image_free(regions);
    ptr_image_free(ranges);
}

/* The passes go into EXR alone, both together; parts with passes do not
 * merge with parts without; a render without --passes has none. */
static void test_refusals(void)
{
    CHECK_INT(test_ptr(SEED_SCENE, "-o", test_path("p.png"), "--width", "16", "--samples", "1",
                       "--passes", "albedo,normal", "--quiet", NULL),
              2);
    CHECK_INT(test_ptr(SEED_SCENE, "-o", test_path("p.exr"), "--passes", "albedo", "--quiet",
                       NULL),
              2);
    PtrImage *with = render_cli("with.exr", "--region", "0,0,48,20", NULL);
    CHECK_INT(test_ptr(SEED_SCENE, "-o", test_path("without.exr"), "--width", "48", "--samples",
                       "8", "--seed", "7", "--region", "0,20,48,48", "--quiet", NULL),
              0);
    CHECK(test_ptr("merge", test_path("with.exr"), test_path("without.exr"), "-o",
                   test_path("no.exr"), "--quiet", NULL) != 0);
    PtrImage *without = NULL;
    PtrError err;
    CHECK_INT(test_image_read(test_path("without.exr"), &without, &err), PTR_OK);
    CHECK(without && !ptr_image_albedo(without) && !ptr_image_normal(without));
    ptr_image_free(with);
    ptr_image_free(without);
}

int main(void)
{
    if (!test_dir_create("passes"))
        return 1;
    const TestCase cases[] = {
        TEST_CASE(test_diffuse),   TEST_CASE(test_mirror),   TEST_CASE(test_fuzzy_metal),
        TEST_CASE(test_threads_and_regions), TEST_CASE(test_merges), TEST_CASE(test_refusals),
    };
    TEST_RUN(cases);
    test_dir_remove();
    return test_report();
}
