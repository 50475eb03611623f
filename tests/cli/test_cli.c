/* The command line end to end, in process: what the executable runs. */
#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>

#include "app/cli.h"
#include "app/cli_options.h"
#include "base/result.h"
#include "image/image.h"
#include "test.h"
#include "test_files.h"

#define SEED_SCENE PTR_SOURCE_DIR "/scenes/seed.gltf"
#define FIXTURE(name) PTR_SOURCE_DIR "/tests/fixtures/" name

static void write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    fputs(text, f);
    fclose(f);
}

static int file_is(const char *path, const char *text)
{
    char buf[256] = { 0 };
    FILE *f = fopen(path, "r");
    if (!f)
        return 0;
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    return n == strlen(text) && !memcmp(buf, text, n);
}

/* Files in the temporary folder: a failed write must leave no temporary. */
static int file_count(void)
{
    DIR *d = opendir(test_dir);
    int n = 0;
    for (struct dirent *e; (e = readdir(d));)
        n += e->d_name[0] != '.' || (strcmp(e->d_name, ".") && strcmp(e->d_name, ".."));
    closedir(d);
    return n;
}

static void test_render_seed_exr(void)
{
    const char *out = test_path("seed.exr");
    CHECK_INT(test_ptr(SEED_SCENE, "-o", out, "--samples", "32", "--width", "60", "--seed", "42",
                  "--quiet", "--c", NULL), 0);
    PtrError err;
    PtrImage *img = NULL;
    CHECK_INT(test_image_read(out, &img, &err), PTR_OK);
    if (!img)
        return;
    /* The scene's camera is square: the height follows the width. */
    CHECK_INT(ptr_image_width(img), 60);
    CHECK_INT(ptr_image_height(img), 60);
    CHECK_STR(ptr_image_attr(img, "ptr:samples"), "32");
    CHECK_STR(ptr_image_attr(img, "ptr:sampler"), "sobol");
    CHECK_STR(ptr_image_attr(img, "ptr:direct_lighting"), "on");
    CHECK_STR(ptr_image_attr(img, "ptr:noise_threshold"), "0");
    CHECK_STR(ptr_image_attr(img, "ptr:seed"), "42");
    CHECK_STR(ptr_image_attr(img, "ptr:kernel"), "c");
    CHECK(ptr_image_attr(img, "Software") && !strncmp(ptr_image_attr(img, "Software"), "ptr ", 4));
    CHECK(ptr_image_attr(img, "ptr:render_seconds") != NULL);

    const float *px = ptr_image_pixels(img);
    /* Top centre looks 44 degrees up into the open gradient sky: with
     * a = (1 + y) / 2 the radiance is (1 - a) + a * (0.5, 0.7, 1.0). Sub-pixel
     * jitter moves y by less than 0.01. */
    double y = sin(44.0 * 3.14159265358979 / 180.0), a = 0.5 * (1 + y);
    const float *top = px + 3 * (0 * 60 + 30);
    CHECK_NEAR(top[0], (1 - a) + a * 0.5, 0.01);
    CHECK_NEAR(top[1], (1 - a) + a * 0.7, 0.01);
    CHECK_NEAR(top[2], 1.0, 1e-6);
    /* The centre is the blue diffuse sphere (albedo 0.1, 0.2, 0.5), lit by
     * the sky and by the yellow ground, which carries no blue: still
     * b > g > r, and darker than the sky that lights it. */
    const float *centre = px + 3 * (30 * 60 + 30);
    CHECK(centre[2] > centre[1] && centre[1] > 1.5f * centre[0]);
    CHECK(centre[2] < 0.5f);
    /* Bottom centre is the yellow ground (albedo 0.8, 0.8, 0): no blue. */
    const float *ground = px + 3 * (59 * 60 + 30);
    CHECK(ground[0] > 0.2f && ground[2] < 0.05f * ground[0]);
    ptr_image_free(img);
}

static void test_png_and_options(void)
{
    const char *png = test_path("seed.png");
    CHECK_INT(test_ptr(SEED_SCENE, "-o", png, "--samples", "2", "--width", "40", "--height", "20",
                  "--sky", "black", "--threads", "1", "--max-depth", "5", "--quiet", NULL), 0);
    PtrError err;
    PtrImage *img = NULL;
    CHECK_INT(test_image_read(png, &img, &err), PTR_OK);
    if (!img)
        return;
    CHECK_INT(ptr_image_width(img), 40);
    CHECK_INT(ptr_image_height(img), 20);
    /* A black sky lights nothing: every 8-bit value is 0. */
    float max = 0;
    for (int i = 0; i < 40 * 20 * 3; i++)
        max = fmaxf(max, ptr_image_pixels(img)[i]);
    CHECK_FLOAT_EQ(max, 0.0f);
    ptr_image_free(img);

    /* A constant sky of 0.5 seen directly encodes to sRGB 0.735 -> code 188. */
    CHECK_INT(test_ptr(SEED_SCENE, "-o", png, "--samples", "1", "--width", "8", "--sky", "0.5,0.5,0.5",
                  "--camera", "Camera", "--quiet", NULL), 0);
    CHECK_INT(test_image_read(png, &img, &err), PTR_OK);
    CHECK_NEAR(ptr_image_pixels(img)[0] * 255.0f, 188.0, 1e-3);
    ptr_image_free(img);
}

/* --ortho: tests/fixtures/orthographic.gltf's Ball (radiance 1, radius 1 at
 * (1, 0, 0)) through a view 4 high from (1, 0, 5), a pixel 0.25 across:
 * the centre sees it, a corner the black sky. Clipped, behind lookfrom, is
 * not seen. */
static void test_orthographic_option(void)
{
    const char *out = test_path("ortho.exr");
    CHECK_INT(test_ptr(FIXTURE("orthographic.gltf"), "-o", out, "--lookfrom", "1,0,5", "--lookat",
                       "1,0,0", "--ortho", "4", "--width", "16", "--height", "16", "--samples",
                       "4", "--quiet", NULL),
              0);
    PtrError err;
    PtrImage *img = NULL;
    CHECK_INT(test_image_read(out, &img, &err), PTR_OK);
    if (!img)
        return;
    const float *px = ptr_image_pixels(img);
    CHECK_FLOAT_EQ(px[3 * (8 * 16 + 8)], 1.0f);
    CHECK_FLOAT_EQ(px[3 * (7 * 16 + 7)], 1.0f);
    CHECK_FLOAT_EQ(px[0], 0.0f);
    ptr_image_free(img);
}

static void test_bad_input(void)
{
    const char *out = test_path("keep.exr");
    const char *keep = "an existing output file";
    int ok_files;
    struct {
        PtrResult expected;
        const char *args[10];
    } cases[] = {
        { PTR_ERR_SCENE_UNREADABLE, { FIXTURE("missing.gltf") } },
        { PTR_ERR_SCENE_UNREADABLE, { FIXTURE("bad") } },
        { PTR_ERR_SCENE_INVALID, { FIXTURE("bad/truncated.gltf") } },
        { PTR_ERR_SCENE_INVALID, { FIXTURE("bad/garbage.glb") } },
        { PTR_ERR_SCENE_INVALID, { PTR_SOURCE_DIR "/CMakeLists.txt" } },
        { PTR_ERR_USAGE, { SEED_SCENE, "--samples", "0" } },
        { PTR_ERR_USAGE, { SEED_SCENE, "--samples", "12x" } },
        { PTR_ERR_USAGE, { SEED_SCENE, "--width", "-3" } },
        { PTR_ERR_USAGE, { SEED_SCENE, "--sky", "0.1,0.2" } },
        { PTR_ERR_USAGE, { SEED_SCENE, "--seed", "18446744073709551616" } },
        { PTR_ERR_USAGE, { SEED_SCENE, "--no-such-option" } },
        { PTR_ERR_SCENE_INVALID, { SEED_SCENE, "--camera", "NoSuchCamera" } },
        { PTR_ERR_USAGE, { SEED_SCENE, "--lookfrom", "0,0,5" } }, /* needs --lookat, --vfov */
        { PTR_ERR_USAGE, { SEED_SCENE, "--lookfrom", "0,0", "--lookat", "0,0,0", "--vfov", "40" } },
        { PTR_ERR_USAGE, { SEED_SCENE, "--vfov", "180" } },
        { PTR_ERR_USAGE, { SEED_SCENE, "--lookfrom", "0,0,5", "--lookat", "0,0,0", "--vfov", "40",
                           "--ortho", "2" } }, /* two projections */
        { PTR_ERR_USAGE,
          { SEED_SCENE, "--lookfrom", "0,0,5", "--lookat", "0,0,0", "--ortho", "0" } },
        { PTR_ERR_USAGE, { SEED_SCENE, "--ortho", "2" } }, /* needs --lookfrom, --lookat */
        { PTR_ERR_USAGE, { SEED_SCENE, "--lookfrom", "0,0,5", "--lookat", "0,0,0", "--ortho", "2",
                           "--aperture", "0.1" } }, /* no lens */
        { PTR_ERR_USAGE, { SEED_SCENE, "--sampler", "halton" } },
        { PTR_ERR_USAGE, { SEED_SCENE, "--direct-lighting", "yes" } },
        { PTR_ERR_USAGE, { SEED_SCENE, "--noise-threshold", "0" } },
        { PTR_ERR_USAGE, { SEED_SCENE, "--noise-threshold", "nan" } },
        { PTR_ERR_USAGE, { SEED_SCENE, "--min-samples", "1" } },
        { PTR_ERR_USAGE, { SEED_SCENE, "--noise-threshold", "0.1", "--sample-range", "4:8" } },
    };
    write_file(out, keep);
    ok_files = file_count();
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char *argv[18] = { "ptr", "-o", (char *)out, "--samples", "1", "--quiet" };
        int argc = 6;
        for (int k = 0; cases[i].args[k]; k++)
            argv[argc++] = (char *)cases[i].args[k];
        int code = ptr_cli_main(argc, argv);
        CHECK_INT(code, ptr_result_exit_code(cases[i].expected));
        if (code != ptr_result_exit_code(cases[i].expected))
            fprintf(stderr, "  case %zu (%s %s)\n", i, cases[i].args[0],
                    cases[i].args[1] ? cases[i].args[1] : "");
        CHECK(file_is(out, keep));
        CHECK_INT(file_count(), ok_files);
    }

    /* Output problems: unknown format, missing folder, a folder as output. */
    CHECK_INT(test_ptr(SEED_SCENE, "-o", test_path("x.unknown"), NULL),
              ptr_result_exit_code(PTR_ERR_USAGE));
    CHECK_INT(test_ptr(SEED_SCENE, "-o", test_path("no/such/dir.exr"), NULL),
              ptr_result_exit_code(PTR_ERR_OUTPUT));
    /* A folder as -o takes NAME.exr. */
    mkdir(test_path("folder"), 0755);
    CHECK_INT(test_ptr(SEED_SCENE, "-o", test_path("folder"), "--samples", "1", "--width", "8",
                  "--quiet", NULL), 0);
    struct stat st;
    CHECK(stat(test_path("folder/seed.exr"), &st) == 0 && st.st_size > 0);
    unlink(test_path("folder/seed.exr"));
    rmdir(test_path("folder"));
    CHECK_INT(test_ptr(SEED_SCENE, NULL), ptr_result_exit_code(PTR_ERR_USAGE));
    CHECK_INT(test_ptr("--help", NULL), 0);
    CHECK_INT(test_ptr("--version", NULL), 0);
    CHECK_INT(file_count(), ok_files);
}

/* --denoise's value is optional: given with '=' or as the next argument if
 * that is a quality (else the argument is an operand); ptr denoise is a
 * merge of one image with --denoise's default, or the quality given. */
static void test_denoise_options(void)
{
    struct {
        const char *args[6];
        int parsed, inputs, command;
        PtrDenoiseQuality quality;
    } cases[] = {
        { { "s.gltf", "--denoise", "fast", "-o", "x.exr" }, 1, 1, 0, PTR_DENOISE_FAST },
        { { "--denoise", "s.gltf", "-o", "x.exr" }, 1, 1, 0, PTR_DENOISE_BALANCED },
        { { "--denoise=high", "s.gltf", "-o", "x.exr" }, 1, 1, 0, PTR_DENOISE_HIGH },
        { { "--denoise", "high", "fast.gltf", "-o", "x.exr" }, 1, 1, 0, PTR_DENOISE_HIGH },
        { { "s.gltf", "-o", "x.exr", "--denoise=slow" }, 0, 0, 0, 0 },
        { { "denoise", "in.exr", "-o", "x.exr" }, 1, 1, 1, PTR_DENOISE_BALANCED },
        { { "denoise", "in.exr", "-o", "x.exr", "--denoise", "fast" }, 1, 1, 1, PTR_DENOISE_FAST },
        { { "denoise", "a.exr", "b.exr", "-o", "x.exr" }, 0, 0, 0, 0 },
        { { "denoise", "-o", "x.exr" }, 0, 0, 0, 0 },
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char *argv[8] = { "ptr" };
        int argc = 1;
        for (int k = 0; k < 6 && cases[i].args[k]; k++)
            argv[argc++] = (char *)cases[i].args[k];
        PtrOptions o;
        PtrError err;
        PtrResult res = ptr_options_parse(argc, argv, &o, &err);
        CHECK_INT(res, cases[i].parsed ? PTR_OK : PTR_ERR_USAGE);
        if (res != PTR_OK || !cases[i].parsed)
            continue;
        CHECK_INT(o.input_count, cases[i].inputs);
        CHECK(o.denoise != NULL);
        CHECK_INT(o.denoise_quality, cases[i].quality);
        CHECK_INT(o.denoise_command, cases[i].command);
        CHECK_INT(o.merge, cases[i].command);
    }
}

/* Image module loaders are their owners' alone: one freed leaves another
 * working, and a caller without one reads EXR only, whatever another has
 * loaded in the same process. */
static void test_image_loaders(void)
{
    const char *png = test_path("loaders.png");
    const float grey[3] = { 0.5f, 0.5f, 0.5f };
    const PtrImageLayout one = { 1, 1, 0, 0, 1, 1 };
    PtrImageLoader *first = NULL, *second = NULL;
    PtrError err;
    CHECK_INT(ptr_image_loader_new(&first, &err), PTR_OK);
    CHECK_INT(ptr_image_loader_new(&second, &err), PTR_OK);
    CHECK_INT(ptr_image_write(first, png, &one, grey, NULL, NULL, PTR_PIXEL_UINT8, NULL, 0, &err),
              PTR_OK);
    ptr_image_loader_free(first);
    PtrImage *img = NULL;
    CHECK_INT(ptr_image_read(NULL, png, &img, &err), PTR_ERR_USAGE);
    CHECK(img == NULL);
    CHECK_INT(ptr_image_read(second, png, &img, &err), PTR_OK);
    CHECK(img && ptr_image_width(img) == 1);
    ptr_image_free(img);
    ptr_image_loader_free(second);
}

int main(void)
{
    if (!test_dir_create("test-cli"))
        return 1;
    const TestCase cases[] = {
        TEST_CASE(test_render_seed_exr),
        TEST_CASE(test_png_and_options),
        TEST_CASE(test_orthographic_option),
        TEST_CASE(test_bad_input),
        TEST_CASE(test_denoise_options),
        TEST_CASE(test_image_loaders),
    };
    TEST_RUN(cases);
    test_dir_remove();
    return test_report();
}
