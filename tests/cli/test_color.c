/* Colour management: ptr's output path against an independent
 * implementation (oiiotool's --ociodisplay) for every view of ptr's config and
 * of a second config; config lookup order; broken configs; unknown names;
 * exposure, bit depths and metadata. */
#include <stdint.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include "app/cli.h"
#include "api/output.h"
#include "base/result.h"
#include "color/color.h"
#include "image/image.h"
#include "test.h"
#include "test_files.h"

#define PTR_CONFIG PTR_SOURCE_DIR "/src/color/config.ocio"
#define SECOND_CONFIG PTR_SOURCE_DIR "/tests/fixtures/ocio/second.ocio"
#define BROKEN_CONFIG PTR_SOURCE_DIR "/tests/fixtures/ocio/broken.ocio"

/* Scene-linear test values: black, the sRGB toe, mid grey, white, over-range
 * and saturated colours. */
static const float inputs[][3] = {
    { 0, 0, 0 },       { 0.0031308f, 0.0031308f, 0.0031308f }, { 0.05f, 0.05f, 0.05f },
    { 0.18f, 0.18f, 0.18f }, { 0.5f, 0.5f, 0.5f }, { 1, 1, 1 },
    { 4, 0.5f, 0.1f }, { 0.05f, 0.3f, 0.9f }, { 16, 16, 16 },
};
enum { N = sizeof inputs / sizeof inputs[0] };

/* The image module's loader the outputs are written and read back through. */
static PtrImageLoader *images;

static PtrOutputInfo info_for(const PtrColor *color)
{
    return (PtrOutputInfo){ .scene_path = "test", .kernel = "c", .samples = 1, .seed = 1,
                            .max_depth = 50, .output = { .color = color } };
}

static PtrImage *read_image(const char *path)
{
    PtrError err;
    PtrImage *img = NULL;
    if (ptr_image_read(images, path, &img, &err) != PTR_OK)
        TEST_FAIL_("%s", err.message);
    return img;
}

/* ptr's 8-bit output against oiiotool's for one display and view. */
static void oracle(const char *config, const char *display, const char *view)
{
    PtrError err;
    char cmd[1024];
    const char *in = test_path("in.exr"), *ours = test_path("ours.png"), *theirs = test_path("theirs.png");
    const PtrImageLayout row = { N, 1, 0, 0, N, 1 };
    CHECK_INT(ptr_image_write(NULL, in, &row, &inputs[0][0], NULL, NULL, PTR_PIXEL_FLOAT, NULL, 0,
                              &err),
              0);

    PtrColor *color = NULL;
    CHECK_INT(ptr_color_open(config, &color, &err), PTR_OK);
    if (!color)
        return;
    CHECK_INT(ptr_color_select(color, display, view, NULL, 0, &err), 0);
    PtrOutputInfo info = info_for(color);
    PtrError perr = { 0 };
    CHECK_INT(ptr_output_write(images, ours, &row, &inputs[0][0], &info, &perr), PTR_OK);
    ptr_color_close(color);

    snprintf(cmd, sizeof cmd, "'%s' --colorconfig '%s' '%s' --ociodisplay '%s' '%s' -d uint8 -o '%s'",
             OIIOTOOL, config, in, display, view, theirs);
    CHECK_INT(system(cmd), 0);
    PtrImage *a = read_image(ours), *b = read_image(theirs);
    if (!a || !b)
        return;
    printf("%-20s %-20s", config == NULL ? "embedded" : strrchr(config, '/') + 1, view);
    int worst = 0;
    for (int i = 0; i < N * 3; i++) {
        int ca = (int)lroundf(ptr_image_pixels(a)[i] * 255), cb = (int)lroundf(ptr_image_pixels(b)[i] * 255);
        worst = abs(ca - cb) > worst ? abs(ca - cb) : worst;
        if (i % 3 == 0)
            printf(" %3d/%-3d", ca, cb);
    }
    printf("  (ptr/oiiotool, red channel; worst difference %d)\n", worst);
    CHECK(worst <= 1);
    ptr_image_free(a);
    ptr_image_free(b);
}

static void test_oracle(void)
{
    printf("%-20s %-20s", "config", "view");
    for (int i = 0; i < N; i++)
        printf(" %7.4g", inputs[i][0]);
    printf("\n");
    /* ptr's embedded config is the file the build embeds; oiiotool reads the file. */
    unsetenv("OCIO");
    const char *ptr_views[] = { "Standard", "ACES 1.0 SDR-video", "Raw" };
    for (int v = 0; v < 3; v++) {
        PtrError err;
        PtrColor *embedded = NULL;
        CHECK_INT(ptr_color_open(NULL, &embedded, &err), PTR_OK);
        CHECK_STR(ptr_color_source(embedded), "embedded");
        ptr_color_close(embedded);
        oracle(PTR_CONFIG, "sRGB", ptr_views[v]);
    }
    const char *second_views[] = { "Gamma", "Log", "Raw" };
    for (int v = 0; v < 3; v++)
        oracle(SECOND_CONFIG, "Gamma 2.2 monitor", second_views[v]);
}

/* The embedded text and the shipped file are the same config. */
static void test_embedded_matches_file(void)
{
    FILE *f = fopen(PTR_CONFIG, "rb");
    CHECK(f != NULL);
    static char text[1 << 16];
    size_t n = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[n] = '\0';
    CHECK_STR(ptr_embedded_ocio_config, text);
}

static void test_lookup_order(void)
{
    PtrError err;
    unsetenv("OCIO");
    PtrColor *c = NULL;
    CHECK_INT(ptr_color_open(NULL, &c, &err), PTR_OK);
    CHECK_STR(ptr_color_source(c), "embedded");
    ptr_color_close(c);

    setenv("OCIO", SECOND_CONFIG, 1);
    CHECK_INT(ptr_color_open(NULL, &c, &err), PTR_OK);
    CHECK_STR(ptr_color_source(c), SECOND_CONFIG);
    CHECK_INT(ptr_color_select(c, NULL, NULL, NULL, 0, &err), 0);
    CHECK_STR(ptr_color_view(c), "Gamma"); /* that config's default */
    ptr_color_close(c);

    CHECK_INT(ptr_color_open(PTR_CONFIG, &c, &err), PTR_OK); /* --ocio-config beats $OCIO */
    CHECK_STR(ptr_color_source(c), PTR_CONFIG);
    ptr_color_close(c);

    /* A broken $OCIO is an error, not a fallback to the embedded config. */
    setenv("OCIO", BROKEN_CONFIG, 1);
    CHECK_INT(ptr_color_open(NULL, &c, &err), PTR_ERR_COLOR);
    CHECK(strstr(err.message, BROKEN_CONFIG) != NULL && strstr(err.message, "$OCIO") != NULL);
    unsetenv("OCIO");
}

static void test_errors(void)
{
    PtrError err;
    PtrColor *c = NULL;
    CHECK_INT(ptr_color_open(BROKEN_CONFIG, &c, &err), PTR_ERR_COLOR);
    CHECK(strstr(err.message, BROKEN_CONFIG) != NULL);
    CHECK_INT(ptr_color_open(PTR_SOURCE_DIR "/no/such.ocio", &c, &err), PTR_ERR_COLOR);
    CHECK_INT(err.code, PTR_ERR_COLOR);

    CHECK_INT(ptr_color_open(NULL, &c, &err), PTR_OK);
    CHECK_INT(ptr_color_select(c, NULL, "Filmic", NULL, 0, &err), PTR_ERR_USAGE);
    CHECK(strstr(err.message, "'Filmic'") && strstr(err.message, "'Standard'") &&
          strstr(err.message, "'Raw'"));
    CHECK_INT(ptr_color_select(c, "Projector", NULL, NULL, 0, &err), PTR_ERR_USAGE);
    CHECK(strstr(err.message, "'sRGB'") != NULL);
    CHECK_INT(ptr_color_select(c, NULL, NULL, "Sepia", 0, &err), PTR_ERR_USAGE);
    CHECK(strstr(err.message, "'Punchy'") != NULL);
    ptr_color_close(c);

    /* Through the command line: exit codes, and the output left alone. */
    const char *out = test_path("keep.png");
    FILE *f = fopen(out, "w");
    fputs("keep", f);
    fclose(f);
    CHECK_INT(test_ptr(PTR_SOURCE_DIR "/scenes/seed.gltf", "-o", out, "--view", "Filmic", NULL),
              ptr_result_exit_code(PTR_ERR_USAGE));
    CHECK_INT(test_ptr(PTR_SOURCE_DIR "/scenes/seed.gltf", "-o", out, "--ocio-config", BROKEN_CONFIG,
                       NULL),
              ptr_result_exit_code(PTR_ERR_COLOR));
    struct stat st;
    CHECK(stat(out, &st) == 0 && st.st_size == 4);
}

/* Exposure, looks, depths and what the files say about themselves. */
static void test_output_path(void)
{
    PtrError err;
    PtrColor *c = NULL;
    CHECK_INT(ptr_color_open(NULL, &c, &err), PTR_OK);
    const float grey[3] = { 0.18f, 0.18f, 0.18f }, doubled[3] = { 0.36f, 0.36f, 0.36f };
    const PtrImageLayout one = { 1, 1, 0, 0, 1, 1 };

    /* +1 stop of 0.18 is 0.36 through the same view. */
    float a[3], b[3];
    memcpy(a, grey, sizeof a);
    memcpy(b, doubled, sizeof b);
    CHECK_INT(ptr_color_select(c, NULL, NULL, NULL, 1.0f, &err), 0);
    ptr_color_apply(c, a, 1, &err);
    CHECK_INT(ptr_color_select(c, NULL, NULL, NULL, 0.0f, &err), 0);
    ptr_color_apply(c, b, 1, &err);
    CHECK_NEAR(a[0], b[0], 1e-6);

    /* The look changes the image; Punchy's CDL darkens mid grey (power 1.2). */
    float looked[3] = { 0.18f, 0.18f, 0.18f };
    CHECK_INT(ptr_color_select(c, NULL, NULL, "Punchy", 0.0f, &err), 0);
    ptr_color_apply(c, looked, 1, &err);
    CHECK_NEAR(looked[0], 0.461356 * pow(0.18, 0.2 / 2.4), 0.01); /* 0.18^1.2 encoded */

    /* 16-bit PNG: 0.18 grey through Standard is sRGB 0.461356, code 30235. */
    CHECK_INT(ptr_color_select(c, NULL, NULL, NULL, 0.0f, &err), 0);
    PtrOutputInfo info = info_for(c);
    PtrError perr = { 0 };
    info.output.depth = PTR_DEPTH_16;
    CHECK_INT(ptr_output_write(images, test_path("grey16.png"), &one, grey, &info, &perr), PTR_OK);
    PtrImage *img = read_image(test_path("grey16.png"));
    CHECK_NEAR(ptr_image_pixels(img)[0] * 65535.0, 30235.0, 1.0);
    CHECK_STR(ptr_image_attr(img, "ptr:view"), "Standard");
    CHECK_STR(ptr_image_attr(img, "oiio:ColorSpace"), "sRGB - Display");
    ptr_image_free(img);

    /* EXR stays scene-linear; --bake-view stores the display-referred values. */
    info.output.depth = PTR_DEPTH_DEFAULT;
    CHECK_INT(ptr_output_write(images, test_path("linear.exr"), &one, grey, &info, &perr), PTR_OK);
    img = read_image(test_path("linear.exr"));
    CHECK_FLOAT_EQ(ptr_image_pixels(img)[0], 0.18f);
    CHECK_STR(ptr_image_attr(img, "ptr:colorspace"), "lin_rec709");
    ptr_image_free(img);
    info.output.bake_view = 1;
    CHECK_INT(ptr_output_write(images, test_path("baked.exr"), &one, grey, &info, &perr), PTR_OK);
    img = read_image(test_path("baked.exr"));
    CHECK_NEAR(ptr_image_pixels(img)[0], 0.461356, 1e-5);
    CHECK_STR(ptr_image_attr(img, "ptr:colorspace"), "sRGB - Display");
    ptr_image_free(img);

    /* Formats refuse depths they cannot hold. */
    CHECK_INT(ptr_output_check(images, test_path("x.jpg"), PTR_DEPTH_16, 0, 0, &perr), PTR_ERR_USAGE);
    CHECK_INT(ptr_output_check(images, test_path("x.exr"), PTR_DEPTH_8, 0, 0, &perr), PTR_ERR_USAGE);
    CHECK_INT(ptr_output_check(images, test_path("x.tif"), PTR_DEPTH_FLOAT, 0, 0, &perr), PTR_OK);
    ptr_color_close(c);
}

int main(void)
{
    PtrError err;
    if (!test_dir_create("test-color") || ptr_image_loader_new(&images, &err) != PTR_OK)
        return 1;
    const TestCase cases[] = {
        TEST_CASE(test_oracle),
        TEST_CASE(test_embedded_matches_file),
        TEST_CASE(test_lookup_order),
        TEST_CASE(test_errors),
        TEST_CASE(test_output_path),
    };
    TEST_RUN(cases);
    ptr_image_loader_free(images);
    test_dir_remove();
    return test_report();
}
