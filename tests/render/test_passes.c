/* The albedo and normal passes (path.h, PtrPathPass): closed forms on a
 * sphere seen head-on (a diffuse sphere's own albedo and its normal towards
 * the camera, the sky clamped where rays miss, a mirror showing what it
 * reflects, tinted by its albedo, a fuzzy metal its own), and the same sums
 * bit for bit whatever the thread count or the regions a render is split
 * into. test_bundles holds the integrators and sample ranges to each
 * other with passes too. */
#include "base/cpu.h"
#include "builder.h"
#include "render/render.h"
#include "test.h"

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

int main(void)
{
    const TestCase cases[] = {
        TEST_CASE(test_diffuse),
        TEST_CASE(test_mirror),
        TEST_CASE(test_fuzzy_metal),
        TEST_CASE(test_threads_and_regions),
    };
    TEST_RUN(cases);
    return test_report();
}
