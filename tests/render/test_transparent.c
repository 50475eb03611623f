/* --transparent: alpha is the share of a pixel's samples whose camera ray hit
 * a sphere, and the colour leaves out what those that missed saw of the sky.
 * Through the command line: alpha on the sky and on spheres, the composite
 * over a constant sky against the ordinary render, the same bytes whatever
 * the threads, integrator, tree and CPU level, merges of regions, straight
 * alpha in PNG, and adaptive sampling that weighs coverage. */
#include "base/cpu.h"
#include "builder.h"
#include "image/image.h"
#include "render/render.h"
#include "test.h"
#include "test_files.h"

#define SEED_SCENE PTR_SOURCE_DIR "/scenes/seed.gltf"
enum { SIZE = 48, SAMPLES = 8, PIXELS = SIZE * SIZE };

/* seed.gltf at SIZE x SIZE, SAMPLES samples, under a constant sky, into
 * name, with the extra options given (NULL-terminated, at most 8). */
static PtrImage *render(const char *name, ...)
{
    const char *out = test_path(name);
    char *argv[24] = { "ptr", SEED_SCENE, "-o", (char *)out, "--width", "48", "--samples", "8",
                       "--sky", "0.3,0.4,0.5", "--quiet", "--seed", "7" };
    int argc = 13;
    va_list ap;
    va_start(ap, name);
    for (char *a; argc < 23 && (a = va_arg(ap, char *));)
        argv[argc++] = a;
    va_end(ap);
    argv[argc] = NULL;
    CHECK_INT(ptr_cli_main(argc, argv), 0);
    PtrError err;
    PtrImage *image = NULL;
    CHECK_INT(test_image_read(out, &image, &err), PTR_OK);
    return image;
}

static int same_pixels(const PtrImage *a, const PtrImage *b)
{
    const float *aa = ptr_image_alpha(a), *ba = ptr_image_alpha(b);
    return !memcmp(ptr_image_pixels(a), ptr_image_pixels(b), PIXELS * 3 * sizeof(float)) &&
           !aa == !ba && (!aa || !memcmp(aa, ba, PIXELS * sizeof(float)));
}

/* The top row looks into the sky over seed.gltf's ground, the centre at its
 * blue sphere: alpha 0 and no colour at all, and alpha 1. Every alpha is a
 * whole number of samples out of 8, and the spheres' edges have some
 * between. Under a constant sky S, the premultiplied colour composited over
 * S, C + (1 - alpha) S, is the ordinary render up to float rounding: both
 * sum the same samples in double, the ordinary one with S added for each
 * sample that missed, and each is rounded to float once, so they differ by
 * about a unit in the last place of a float: at most 2^-22 (two of them at
 * 1.0) times the larger of 1 and the value. */
static void test_alpha_and_composite(void)
{
    PtrImage *t = render("t.exr", "--transparent", NULL), *o = render("o.exr", NULL);
    if (!t || !o)
        return;
    const float *alpha = ptr_image_alpha(t), *c = ptr_image_pixels(t), *ref = ptr_image_pixels(o);
    CHECK(alpha != NULL);
    CHECK(ptr_image_alpha(o) == NULL);
    if (!alpha)
        return;
    const int top = SIZE / 2, centre = (SIZE / 2) * SIZE + SIZE / 2;
    CHECK_FLOAT_EQ(alpha[top], 0.0f);
    for (int k = 0; k < 3; k++)
        CHECK_FLOAT_EQ(c[3 * top + k], 0.0f);
    CHECK_FLOAT_EQ(alpha[centre], 1.0f);
    int fractional = 0, whole_samples = 1;
    const double sky[3] = { 0.3, 0.4, 0.5 };
    double worst = 0;
    for (int p = 0; p < PIXELS; p++) {
        double a = alpha[p], covered = a * SAMPLES;
        whole_samples &= fabs(covered - round(covered)) < 1e-6;
        fractional += a > 0 && a < 1;
        for (int k = 0; k < 3; k++) {
            double composite = (double)c[3 * p + k] + (1.0 - a) * (double)(float)sky[k];
            double error = fabs(composite - ref[3 * p + k]) / fmax(1.0, fabs(ref[3 * p + k]));
            worst = fmax(worst, error);
        }
    }
    CHECK(whole_samples);
    CHECK(fractional > 0);
    printf("composite over the sky against the ordinary render: worst relative error %.3g\n",
           worst);
    CHECK(worst <= 0x1p-22);
    ptr_image_free(t);
    ptr_image_free(o);
}

/* The same bytes with one thread and the one-path integrator over brute
 * force, two threads and bundles over the tree, the C reference with the CPU
 * capped at no vector extension, and then, where the build and the CPU have
 * them, the assembly kernels: the cap was that render's alone (a cap kept
 * by the process would refuse --asm, and cap every case after this one). */
static void test_same_bytes(void)
{
    const int have_asm = ptr_isect_has_asm() && ptr_cpu_level() >= PTR_CPU_SSE41;
    PtrImage *a = render("a.exr", "--transparent", "--threads", "1", "--integrator", "paths",
                         "--accel", "brute", NULL);
    const char *integrator =
        ptr_integrator_available(PTR_INTEGRATOR_BUNDLES, ptr_cpu_level()) ? "bundles" : "paths";
    PtrImage *b = render("b.exr", "--transparent", "--threads", "2", "--integrator", integrator,
                         "--accel", "bvh", NULL);
    PtrImage *c = render("c.exr", "--transparent", "--threads", "2", "--cpumask", "none",
                         "--integrator", "paths", "--c", NULL);
    PtrImage *d = have_asm ? render("d.exr", "--transparent", "--asm", NULL) : NULL;
    if (a && b && c) {
        CHECK(same_pixels(a, b));
        CHECK(same_pixels(a, c));
    }
    if (a && d)
        CHECK(same_pixels(a, d));
    ptr_image_free(a);
    ptr_image_free(b);
    ptr_image_free(c);
    ptr_image_free(d);
}

/* Two regions merged: the whole render's bytes, alpha included. */
static void test_regions_merge(void)
{
    PtrImage *whole = render("whole.exr", "--transparent", NULL);
    PtrImage *top = render("top.exr", "--transparent", "--region", "0,0,48,20", NULL);
    PtrImage *bottom = render("bottom.exr", "--transparent", "--region", "0,20,48,48", NULL);
    CHECK_INT(test_ptr("merge", test_path("top.exr"), test_path("bottom.exr"), "-o",
                       test_path("merged.exr"), "--quiet", NULL),
              0);
    PtrError err;
    PtrImage *merged = NULL;
    CHECK_INT(test_image_read(test_path("merged.exr"), &merged, &err), PTR_OK);
    CHECK(merged && ptr_image_alpha(merged));
    if (whole && merged)
        CHECK(same_pixels(whole, merged));
    /* A transparent part and an opaque one are not parts of one render. */
    ptr_image_free(render("opaque_bottom.exr", "--region", "0,20,48,48", NULL));
    CHECK_INT(test_ptr("merge", test_path("top.exr"), test_path("opaque_bottom.exr"), "-o",
                       test_path("mixed.exr"), "--quiet", NULL),
              2);
    ptr_image_free(whole);
    ptr_image_free(top);
    ptr_image_free(bottom);
    ptr_image_free(merged);
}

/* PNG holds straight alpha, rounded to 8 bits: where every sample hit, the
 * ordinary PNG's colour; on the sky, alpha 0; between, the EXR's alpha. A
 * format without alpha is refused before rendering. */
static void test_png(void)
{
    PtrImage *exr = render("p.exr", "--transparent", NULL);
    PtrImage *png = render("p.png", "--transparent", NULL), *plain = render("plain.png", NULL);
    if (!exr || !png || !plain)
        return;
    const float *alpha = ptr_image_alpha(exr), *png_alpha = ptr_image_alpha(png);
    CHECK(png_alpha != NULL);
    if (!alpha || !png_alpha)
        return;
    int covered_same = 1, alpha_same = 1;
    for (int p = 0; p < PIXELS; p++) {
        alpha_same &= fabsf(png_alpha[p] - alpha[p]) <= 0.5f / 255 + 1e-6f;
        if (alpha[p] == 1.0f)
            covered_same &= !memcmp(ptr_image_pixels(png) + 3 * p,
                                    ptr_image_pixels(plain) + 3 * p, 3 * sizeof(float));
    }
    CHECK(alpha_same);
    CHECK(covered_same);
    CHECK_INT(test_ptr(SEED_SCENE, "-o", test_path("x.jpg"), "--transparent", "--quiet", NULL), 2);
    ptr_image_free(exr);
    ptr_image_free(png);
    ptr_image_free(plain);
}

/* Adaptive sampling weighs alpha as a channel: a black sphere under a black
 * sky has no colour anywhere, so without --transparent every pixel stops at
 * the first check; with it, pixels wholly on or off the sphere stop there
 * too (their alpha never varies), and its edge samples on. */
static void test_adaptive(void)
{
    PtrScene scene;
    ptr_scene_init(&scene);
    uint32_t black;
    const PtrMaterial m = { .kind = PTR_MATERIAL_DIFFUSE, .albedo = v3_splat(0.0f) };
    CHECK_INT(ptr_scene_add_material(&scene, &m, &black, NULL), PTR_OK);
    PtrSceneBuilder b;
    ptr_builder_init(&b, &scene, NULL);
    const double centre[3] = { 0, 0, 0 }, eye[3] = { 0, 0, 5 }, up[3] = { 0, 1, 0 };
    CHECK_INT(ptr_builder_add_sphere(&b, centre, 1.0, black, NULL), PTR_OK);
    const PtrCamera lens = { .vfov_deg = 40.0f, .focus_distance = 5.0f };
    ptr_builder_set_camera(&b, eye, centre, up, &lens);
    CHECK_INT(ptr_builder_finish(&b, PTR_BUILD_DEFAULT, NULL), PTR_OK);
    scene.sky.kind = PTR_SKY_BLACK;
    PtrIsectTable isect;
    ptr_isect_init(&isect, PTR_KERNEL_AUTO, ptr_cpu_level(), scene.spheres.count, NULL);
    const PtrAccel accel = ptr_accel_brute(&isect, &scene);
    PtrRenderSettings s = { .width = 32, .height = 32, .seed = 3, .max_depth = 8, .threads = 2,
                            .noise_threshold = 0.01f, .min_samples = 16 };
    enum { N = 32 * 32, MAX = 256 };
    static float rgb[N * 3], alpha[N], counts[N];
    int stopped_early[2] = { 0, 0 }, edge_sampled_on = 0, whole_stopped = 1;
    for (int transparent = 0; transparent < 2; transparent++) {
        s.transparent = transparent;
        double *acc = ptr_accum_alloc(N, PTR_ACCUM_STRIDE);
        PtrError err = { 0 };
        CHECK_INT(ptr_render_samples(&scene, &accel, &s, 0, MAX, acc, NULL, NULL, NULL, &err),
                  PTR_OK);
        ptr_accum_resolve(acc, N, PTR_ACCUM_STRIDE, rgb, alpha, counts);
        ptr_accum_free(acc, N, PTR_ACCUM_STRIDE);
        for (int p = 0; p < N; p++) {
            stopped_early[transparent] += counts[p] == 16;
            if (transparent && (alpha[p] == 0.0f || alpha[p] == 1.0f))
                whole_stopped &= counts[p] == 16;
            if (transparent && alpha[p] > 0.0f && alpha[p] < 1.0f)
                edge_sampled_on += counts[p] > 16;
        }
    }
    CHECK_INT(stopped_early[0], N);
    CHECK(whole_stopped);
    printf("adaptive: %d edge pixels sampled past the first check\n", edge_sampled_on);
    CHECK(edge_sampled_on > 0);
    ptr_scene_free(&scene);
}

/* The automatic camera, seen in the alpha of a camera-less scene at 160x90:
 * its spheres span 18 units across and 7 up, so the width binds and they
 * cover 95% of it, 152 columns, centred (4 empty on each side); a pixel
 * the silhouette crosses counts, so the span may reach a column further on
 * each side. The height holds them with rows to spare. */
static void test_framing(const char *projection)
{
    const char *out = test_path("framed.exr");
    CHECK_INT(test_ptr(PTR_SOURCE_DIR "/tests/fixtures/no_camera.gltf", "-o", out, "--width",
                       "160", "--height", "90", "--samples", "16", "--transparent",
                       "--auto-camera", projection, "--quiet", NULL),
              0);
    PtrError err;
    PtrImage *image = NULL;
    CHECK_INT(test_image_read(out, &image, &err), PTR_OK);
    const float *alpha = image ? ptr_image_alpha(image) : NULL;
    CHECK(alpha != NULL);
    if (!alpha) {
        ptr_image_free(image);
        return;
    }
    int left = 160, right = -1, top = 90, bottom = -1;
    for (int y = 0; y < 90; y++)
        for (int x = 0; x < 160; x++)
            if (alpha[y * 160 + x] > 0.0f) {
                left = x < left ? x : left;
                right = x > right ? x : right;
                top = y < top ? y : top;
                bottom = y > bottom ? y : bottom;
            }
    printf("%s framing: columns %d to %d, rows %d to %d\n", projection, left, right, top, bottom);
    CHECK(right - left + 1 >= 152 && right - left + 1 <= 154);
    CHECK(left >= 3 && left <= 4 && right >= 155 && right <= 156);
    CHECK(top > 0 && bottom < 89);
    ptr_image_free(image);
}

static void test_framing_perspective(void)
{
    test_framing("perspective");
}

static void test_framing_orthographic(void)
{
    test_framing("orthographic");
}

int main(void)
{
    if (!test_dir_create("transparent"))
        return 1;
    const TestCase cases[] = {
        TEST_CASE(test_same_bytes),          TEST_CASE(test_alpha_and_composite),
        TEST_CASE(test_regions_merge),       TEST_CASE(test_png),
        TEST_CASE(test_adaptive),            TEST_CASE(test_framing_perspective),
        TEST_CASE(test_framing_orthographic),
    };
    TEST_RUN(cases);
    test_dir_remove();
    return test_report();
}
