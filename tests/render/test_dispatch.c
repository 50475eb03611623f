/* Every intersector gives the same image, byte for byte: through the library
 * at each CPU level this machine has, and through the command line's EXR
 * files with --c and --asm. */
#include <stdarg.h>
#include <unistd.h>

#include "app/cli.h"
#include "base/cpu.h"
#include "image/image.h"
#include "importer.h"
#include "render/render.h"
#include "test.h"

static float *render_with(const PtrScene *scene, const PtrIsectTable *isect,
                          const PtrRenderSettings *settings)
{
    float *rgb = malloc((size_t)settings->width * settings->height * 3 * sizeof *rgb);
    PtrError err = { 0 };
    const PtrAccel accel = ptr_accel_brute(isect, scene);
    CHECK_INT(ptr_render(scene, &accel, settings, rgb, NULL, &err), PTR_OK);
    return rgb;
}

static void check_levels(const char *path, int width, int height)
{
    PtrScene scene;
    PtrStrings warnings = { 0 };
    PtrError err = { 0 };
    CHECK_INT(ptr_import_scene(path, NULL, &scene, &warnings, &err), PTR_OK);
    ptr_strings_free(&warnings);
    PtrRenderSettings settings = { .width = width, .height = height, .samples = 4, .seed = 3,
                                   .max_depth = 50, .threads = 2 };
    PtrIsectTable c;
    ptr_isect_init_level(&c, PTR_CPU_NONE);
    float *reference = render_with(&scene, &c, &settings);
    size_t bytes = (size_t)width * height * 3 * sizeof(float);
    /* main skips below SSE4.1: at least one level is compared. */
    for (int l = PTR_CPU_SSE41; l <= (int)ptr_cpu_level(); l++) {
        PtrIsectTable t;
        ptr_isect_init_level(&t, (PtrCpuLevel)l);
        /* Every level from SSE4.1 on has assembly of its own. */
        CHECK(t.closest_hit != c.closest_hit);
        float *rgb = render_with(&scene, &t, &settings);
        int same = !memcmp(rgb, reference, bytes);
        CHECK(same);
        printf("%s: %s %s c\n", path, t.name, same ? "==" : "!=");
        free(rgb);
    }
    free(reference);
    ptr_scene_free(&scene);
}

static PtrImage *render_file(const char *scene, const char *out, const char *kernel)
{
    char *argv[] = { "ptr", (char *)scene, "-o", (char *)out, "--width", "96", "--samples", "3",
                     "--quiet", (char *)kernel, NULL };
    CHECK_INT(ptr_cli_main(10, argv), 0);
    PtrError err;
    PtrImage *img = NULL;
    CHECK_INT(ptr_image_read(NULL, out, &img, &err), PTR_OK);
    return img;
}

static void check_cli(const char *scene)
{
    char dir[] = "/tmp/ptr-dispatch-XXXXXX", c_path[64], asm_path[64];
    CHECK(mkdtemp(dir) != NULL);
    snprintf(c_path, sizeof c_path, "%s/c.exr", dir);
    snprintf(asm_path, sizeof asm_path, "%s/asm.exr", dir);
    PtrImage *c = render_file(scene, c_path, "--c");
    PtrImage *a = render_file(scene, asm_path, "--asm");
    if (c && a) {
        CHECK_STR(ptr_image_attr(c, "ptr:kernel"), "c");
        CHECK(strcmp(ptr_image_attr(a, "ptr:kernel"), "c") != 0);
        size_t bytes = (size_t)ptr_image_width(c) * ptr_image_height(c) * 3 * sizeof(float);
        CHECK(ptr_image_width(a) == ptr_image_width(c) && ptr_image_height(a) == ptr_image_height(c));
        CHECK(!memcmp(ptr_image_pixels(c), ptr_image_pixels(a), bytes));
    }
    ptr_image_free(c);
    ptr_image_free(a);
    unlink(c_path);
    unlink(asm_path);
    rmdir(dir);
}

static void test_levels_seed(void)
{
    check_levels(PTR_SOURCE_DIR "/scenes/seed.gltf", 100, 100);
}

static void test_levels_final(void)
{
    check_levels(PTR_SOURCE_DIR "/scenes/final.gltf", 160, 90);
}

static void test_levels_lamps(void) /* shadow rays too */
{
    check_levels(PTR_SOURCE_DIR "/scenes/lamps.gltf", 160, 90);
}

static void test_cli_seed(void)
{
    check_cli(PTR_SOURCE_DIR "/scenes/seed.gltf");
}

static void test_cli_final(void)
{
    check_cli(PTR_SOURCE_DIR "/scenes/final.gltf");
}

int main(void)
{
    if (!ptr_isect_has_asm())
        return test_skip("a build without assembly (PTR_ENABLE_ASM=OFF, no nasm, or not x86-64): "
                         "no intersector to compare with C");
    if (ptr_cpu_level() < PTR_CPU_SSE41)
        return test_skip("CPU level below SSE4.1 (or PTR_CPUMASK=none): no assembly runs");
    const TestCase cases[] = {
        TEST_CASE(test_levels_seed), TEST_CASE(test_levels_final), TEST_CASE(test_levels_lamps),
        TEST_CASE(test_cli_seed),    TEST_CASE(test_cli_final),
    };
    TEST_RUN(cases);
    return test_report();
}
