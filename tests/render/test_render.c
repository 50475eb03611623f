/* Whole renders with closed-form answers (through perspective and
 * orthographic cameras), and determinism across threads. */
#include <stdint.h>

#include "importer.h"
#include "render/render.h"
#include "test.h"

typedef struct Image {
    int width, height;
    float *rgb;
} Image;

static Image render(const PtrScene *scene, PtrRenderSettings settings)
{
    PtrIsectTable isect;
    ptr_isect_init(&isect, PTR_KERNEL_C, ptr_cpu_level(), scene->spheres.count, NULL);
    const PtrAccel accel = ptr_accel_brute(&isect, scene);
    Image img = { settings.width, settings.height,
                  malloc((size_t)settings.width * settings.height * 3 * sizeof(float)) };
    PtrError err = { 0 };
    CHECK_INT(ptr_render(scene, &accel, &settings, img.rgb, NULL, &err), PTR_OK);
    return img;
}

/* One sphere of the given material at the origin, seen from distance 5
 * through a 20 degree field of view (the sphere subtends 23 degrees), in a
 * constant sky of radiance 1. */
static PtrScene furnace(PtrMaterial material)
{
    PtrScene s;
    uint32_t m;
    ptr_scene_init(&s);
    CHECK_INT(ptr_scene_add_material(&s, &material, &m, NULL), PTR_OK);
    CHECK_INT(ptr_scene_add_sphere(&s, v3(0, 0, 0), 1.0f, m, NULL), PTR_OK);
    s.sky = (PtrSky){ .kind = PTR_SKY_CONSTANT, .radiance = v3_splat(1.0f) };
    s.camera = (PtrCamera){ .lookfrom = v3(0, 0, 5), .lookat = v3(0, 0, 0),
                            .up = v3(0, 1, 0), .vfov_deg = 20.0f, .focus_distance = 5.0f };
    return s;
}

/* Every pixel of the central 8x8 block of a 16x16 image lies well inside the
 * sphere's disc: each must equal the expected radiance exactly. */
static void check_centre(const Image *img, float expected, const char *what)
{
    int wrong = 0;
    for (int y = 4; y < 12; y++)
        for (int x = 4; x < 12; x++)
            for (int c = 0; c < 3; c++)
                if (img->rgb[3 * (y * 16 + x) + c] != expected) {
                    if (!wrong)
                        fprintf(stderr, "%s: pixel (%d, %d) is %.9g, not %.9g\n", what, x, y,
                                img->rgb[3 * (y * 16 + x) + c], expected);
                    wrong++;
                }
    CHECK_INT(wrong, 0);
}

static void test_furnaces(void)
{
    const PtrRenderSettings settings = { .width = 16, .height = 16, .samples = 16, .seed = 1,
                                         .max_depth = 50, .threads = 2 };
    struct {
        const char *what;
        PtrMaterial material;
        float expected;
    } cases[] = {
        { "diffuse 0.5", { .kind = PTR_MATERIAL_DIFFUSE, .albedo = v3_splat(0.5f) }, 0.5f },
        { "mirror 0.7", { .kind = PTR_MATERIAL_METAL, .albedo = v3_splat(0.7f) }, 0.7f },
        { "clear glass", { .kind = PTR_MATERIAL_DIELECTRIC, .albedo = v3_splat(1), .ior = 1.5f },
          1.0f },
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        PtrScene s = furnace(cases[i].material);
        Image img = render(&s, settings);
        check_centre(&img, cases[i].expected, cases[i].what);
        free(img.rgb);
        ptr_scene_free(&s);
    }
}

/* A camera inside a diffuse emitter of albedo a and emission E: every path
 * hits the wall max_depth times, so each pixel is E * (1 + a + ... + a^(D-1)).
 * Light sampling keeps it exact: from a point on a sphere's inside, a
 * uniform point of its surface has the very density cos / pi of scattering
 * (the chord makes the same angle with both ends' normals), so every light
 * sample carries a E and both MIS weights are 1/2. */
static void test_inside_emitter(void)
{
    PtrMaterial wall = { .kind = PTR_MATERIAL_DIFFUSE, .albedo = v3_splat(0.5f),
                         .emission = v3_splat(1.0f) };
    PtrScene s = furnace(wall);
    s.spheres.radius[0] = 100.0f;
    s.sky.kind = PTR_SKY_BLACK;
    PtrRenderSettings settings = { .width = 16, .height = 16, .samples = 4, .seed = 1,
                                   .max_depth = 3, .threads = 1 };
    Image img = render(&s, settings);
    check_centre(&img, 1.75f, "emitter, depth 3");
    free(img.rgb);

    settings.max_depth = 50;
    img = render(&s, settings);
    int wrong = 0;
    for (int i = 0; i < 16 * 16 * 3; i++)
        wrong += fabs(img.rgb[i] - 2.0 * (1.0 - pow(0.5, 50))) > 2.4e-7;
    CHECK_INT(wrong, 0);
    free(img.rgb);
    ptr_scene_free(&s);
}

/* Thread counts give the same bits, seeds others: on seed.gltf, and on
 * lamps.gltf (light sampling, glass and metal) with either sampler. */
static void check_thread_independence(const char *path, PtrSamplerKind sampler)
{
    PtrScene s;
    PtrStrings warnings = { 0 };
    PtrError err = { 0 };
    CHECK_INT(ptr_import_scene(path, NULL, &s, &warnings, &err), PTR_OK);
    ptr_strings_free(&warnings);
    PtrRenderSettings settings = { .width = 67, .height = 43, .samples = 3, .seed = 9,
                                   .max_depth = 50, .threads = 1, .sampler = sampler };
    Image one = render(&s, settings);
    settings.threads = 2;
    Image two = render(&s, settings);
    settings.threads = 7;
    Image seven = render(&s, settings);
    size_t bytes = 67 * 43 * 3 * sizeof(float);
    CHECK(memcmp(one.rgb, two.rgb, bytes) == 0);
    CHECK(memcmp(one.rgb, seven.rgb, bytes) == 0);
    settings.seed = 10;
    Image other = render(&s, settings);
    CHECK(memcmp(one.rgb, other.rgb, bytes) != 0);
    free(one.rgb);
    free(two.rgb);
    free(seven.rgb);
    free(other.rgb);
    ptr_scene_free(&s);
}

static void test_thread_independence(void)
{
    check_thread_independence(PTR_SOURCE_DIR "/scenes/seed.gltf", PTR_SAMPLER_SOBOL);
    check_thread_independence(PTR_SOURCE_DIR "/scenes/lamps.gltf", PTR_SAMPLER_SOBOL);
    check_thread_independence(PTR_SOURCE_DIR "/scenes/lamps.gltf", PTR_SAMPLER_INDEPENDENT);
}

/* An orthographic camera at (0, 0, 10) looking down -Z with a view
 * 2 ymag high. */
static PtrCamera orthographic(float ymag)
{
    return (PtrCamera){ .lookfrom = v3(0, 0, 10), .lookat = v3(0, 0, 0), .up = v3(0, 1, 0),
                        .projection = PTR_PROJECTION_ORTHOGRAPHIC, .ymag = ymag };
}

/* Checks an image of size x size pixels showing radiance 1 on a disc of
 * radius r about (cx, cy) (world units from the view's centre, y up) and
 * 0 elsewhere, a pixel being world units wide: every pixel wholly inside is
 * exactly 1, every one wholly outside exactly 0. Returns the disc's area as
 * the image measures it. */
static double check_disc(const Image *img, int size, double pixel, double cx, double cy,
                         double r)
{
    int wrong = 0;
    double sum = 0;
    for (int y = 0; y < size; y++)
        for (int x = 0; x < size; x++) {
            /* The pixel's square relative to the centre, and its nearest
             * and farthest points from it. */
            double x0 = (x - 0.5 * size) * pixel - cx, y0 = (0.5 * size - y - 1) * pixel - cy;
            double nx = fmax(fmax(x0, -(x0 + pixel)), 0), ny = fmax(fmax(y0, -(y0 + pixel)), 0);
            double fx = fmax(fabs(x0), fabs(x0 + pixel)), fy = fmax(fabs(y0), fabs(y0 + pixel));
            float v = img->rgb[3 * (y * size + x)];
            sum += v;
            if ((hypot(fx, fy) < r && v != 1.0f) || (hypot(nx, ny) > r && v != 0.0f))
                wrong++;
        }
    CHECK_INT(wrong, 0);
    return sum * pixel * pixel;
}

/* Seen orthographically, a sphere of radius r is a disc of radius r
 * wherever it lies: an emitter of radiance 1 under a black sky, off the
 * view's axis. */
static void test_orthographic_disc(void)
{
    PtrScene s;
    uint32_t m;
    ptr_scene_init(&s);
    const PtrMaterial lamp = { .kind = PTR_MATERIAL_DIFFUSE, .emission = v3_splat(1.0f) };
    CHECK_INT(ptr_scene_add_material(&s, &lamp, &m, NULL), PTR_OK);
    const double r = 1.5, cx = 0.25, cy = -0.125;
    CHECK_INT(ptr_scene_add_sphere(&s, v3((float)cx, (float)cy, -3), (float)r, m, NULL), PTR_OK);
    s.sky.kind = PTR_SKY_BLACK;
    s.camera = orthographic(2.0f);
    const PtrRenderSettings settings = { .width = 64, .height = 64, .samples = 64, .seed = 1,
                                         .max_depth = 5, .threads = 2 };
    Image img = render(&s, settings);
    double area = check_disc(&img, 64, 4.0 / 64, cx, cy, r);
    /* Only the ~150 pixels the edge crosses estimate their coverage, each
     * from 64 stratified samples (an error of a sample or two at most, of
     * either sign): well within 1% of the 1810 pixels the disc covers. */
    CHECK_NEAR(area, 3.14159265358979 * r * r, 0.01 * 3.14159265358979 * r * r);
    free(img.rgb);
    ptr_scene_free(&s);
}

/* A white diffuse sphere under a uniform sky of radiance 1, seen
 * orthographically, is invisible: a path off a convex sphere's outside
 * never meets it again, so every path brings back the sky's 1 times albedo
 * 1, exactly, and every pixel, on the sphere or not, is 1 with no
 * statistical tolerance at all. */
static void test_orthographic_furnace(void)
{
    PtrScene s = furnace((PtrMaterial){ .kind = PTR_MATERIAL_DIFFUSE, .albedo = v3_splat(1.0f) });
    s.camera = orthographic(1.5f);
    const PtrRenderSettings settings = { .width = 24, .height = 16, .samples = 16, .seed = 3,
                                         .max_depth = 50, .threads = 2 };
    Image img = render(&s, settings);
    int wrong = 0;
    for (int i = 0; i < 24 * 16 * 3; i++)
        wrong += img.rgb[i] != 1.0f;
    CHECK_INT(wrong, 0);
    free(img.rgb);
    ptr_scene_free(&s);
}

/* tests/fixtures/orthographic.gltf: emitters of radiance 1 (Ball, radius 1,
 * on the view's axis), 0.25 (Clipped, between the camera and its near plane)
 * and 0.5 (Far, 2 right of the axis, beyond zfar) under a black sky, seen
 * through a view 4 high and, from xmag / ymag, 1.5 times as wide. */
static void test_orthographic_gltf(void)
{
    PtrScene s;
    PtrStrings warnings = { 0 };
    PtrError err = { 0 };
    CHECK_INT(ptr_import_scene(PTR_SOURCE_DIR "/tests/fixtures/orthographic.gltf", NULL, &s,
                               &warnings, &err),
              PTR_OK);
    ptr_strings_free(&warnings);
    const PtrRenderSettings settings = { .width = 48, .height = 32, .samples = 16, .seed = 1,
                                         .max_depth = 5, .threads = 2 };
    Image img = render(&s, settings); /* 0.125 world units a pixel */
    const float *px = img.rgb;
    /* The centre: Ball, not Clipped, which the near plane cuts away. */
    CHECK_FLOAT_EQ(px[3 * (15 * 48 + 23)], 1.0f);
    CHECK_FLOAT_EQ(px[3 * (16 * 48 + 24)], 1.0f);
    /* Far, 16 pixels right: zfar does not clip. */
    CHECK_FLOAT_EQ(px[3 * (16 * 48 + 40)], 0.5f);
    /* A corner sees the sky. */
    CHECK_FLOAT_EQ(px[0], 0.0f);
    free(img.rgb);
    ptr_scene_free(&s);
}

int main(void)
{
    const TestCase cases[] = {
        TEST_CASE(test_furnaces),
        TEST_CASE(test_inside_emitter),
        TEST_CASE(test_thread_independence),
        TEST_CASE(test_orthographic_disc),
        TEST_CASE(test_orthographic_furnace),
        TEST_CASE(test_orthographic_gltf),
    };
    TEST_RUN(cases);
    return test_report();
}
