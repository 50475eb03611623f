/* Renders in parts: passes, sample ranges, regions, merge, batches, time
 * budgets and previews, driven in process through the library and the command
 * line. */
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "app/cli.h"
#include "base/result.h"
#include "image/image.h"
#include "importer.h"
#include "render/render.h"
#include "test.h"
#include "test_files.h"

#define SEED_SCENE PTR_SOURCE_DIR "/scenes/seed.gltf"
#define FINAL_SCENE PTR_SOURCE_DIR "/scenes/final.gltf"
#define LAMPS_SCENE PTR_SOURCE_DIR "/scenes/lamps.gltf"

static PtrImage *load(const char *path)
{
    PtrError err;
    PtrImage *img = NULL;
    if (test_image_read(path, &img, &err) != PTR_OK)
        TEST_FAIL_("%s", err.message);
    return img;
}

/* Passes of any size sum to exactly the bits of one pass: on seed.gltf,
 * and on lamps.gltf (light sampling) with and without adaptive sampling,
 * which must then stop some pixels and not others. */
static void check_passes(const char *path, float noise_threshold)
{
    PtrScene scene;
    PtrStrings warnings = { 0 };
    PtrError err = { 0 };
    CHECK_INT(ptr_import_scene(path, NULL, &scene, &warnings, &err), PTR_OK);
    ptr_strings_free(&warnings);
    PtrIsectTable isect;
    ptr_isect_init(&isect, PTR_KERNEL_AUTO, ptr_cpu_level(), scene.spheres.count, NULL);
    const PtrAccel accel = ptr_accel_brute(&isect, &scene);
    PtrRenderSettings s = { .width = 40, .height = 40, .seed = 5, .max_depth = 50,
                            .noise_threshold = noise_threshold, .min_samples = 16 };
    static double one[40 * 40 * PTR_ACCUM_STRIDE], parts[40 * 40 * PTR_ACCUM_STRIDE];
    memset(one, 0, sizeof one);
    memset(parts, 0, sizeof parts);
    CHECK_INT(ptr_render_samples(&scene, &accel, &s, 0, 48, one, NULL, NULL, NULL, &err), PTR_OK);
    const uint32_t cuts[] = { 0, 1, 4, 17, 31, 48 };
    for (int i = 0; i < 5; i++)
        CHECK_INT(ptr_render_samples(&scene, &accel, &s, cuts[i], cuts[i + 1] - cuts[i], parts,
                                     NULL, NULL, NULL, &err), PTR_OK);
    CHECK(!memcmp(one, parts, sizeof one));
    int stopped = 0;
    for (int p = 0; p < 40 * 40; p++)
        stopped += one[p * PTR_ACCUM_STRIDE + PTR_ACCUM_COUNT] < 48;
    if (noise_threshold > 0) {
        printf("%s: adaptive sampling stopped %d of %d pixels before 48 samples\n", path, stopped,
               40 * 40);
        CHECK(stopped > 0 && stopped < 40 * 40);
    } else {
        CHECK_INT(stopped, 0);
    }
    ptr_scene_free(&scene);
}

static void test_passes_are_exact(void)
{
    check_passes(SEED_SCENE, 0);
    check_passes(LAMPS_SCENE, 0);
    check_passes(LAMPS_SCENE, 0.05f);
}

/* Adaptive sampling: regions merged equal the whole render bit for bit, the
 * EXR holds each pixel's sample count, and a later sample range or
 * overlapping adaptive parts are refused. */
static void test_adaptive_parts(void)
{
    const int usage = ptr_result_exit_code(PTR_ERR_USAGE);
    const char *whole = test_path("adaptive.exr");
    CHECK_INT(test_ptr(LAMPS_SCENE, "-o", whole, "--width", "80", "--samples", "64",
                       "--noise-threshold", "0.05", "--min-samples", "16", "--quiet", NULL), 0);
    const char *regions[] = { "0,0,80,20", "0,20,80,45" };
    for (int i = 0; i < 2; i++) {
        char name[32];
        snprintf(name, sizeof name, "adaptive%d.exr", i);
        CHECK_INT(test_ptr(LAMPS_SCENE, "-o", test_path(name), "--width", "80", "--samples", "64",
                           "--noise-threshold", "0.05", "--min-samples", "16", "--region", regions[i],
                           "--threads", i ? "1" : "2", "--quiet", NULL), 0);
    }
    CHECK_INT(test_ptr("merge", test_path("adaptive0.exr"), test_path("adaptive1.exr"), "-o",
                       test_path("adaptive-tiles.exr"), "--quiet", NULL), 0);
    PtrImage *a = load(whole), *b = load(test_path("adaptive-tiles.exr"));
    if (a && b)
        CHECK(!memcmp(ptr_image_pixels(a), ptr_image_pixels(b), 80 * 45 * 3 * sizeof(float)));
    if (a)
        CHECK_STR(ptr_image_attr(a, "ptr:noise_threshold"), "0.05");
    ptr_image_free(a);
    ptr_image_free(b);

    /* The samples channel: whole counts from 16 to 64, not all alike. */
    char command[1024];
    snprintf(command, sizeof command, "%s %s --ch samples --printinfo:stats=1", OIIOTOOL, whole);
    FILE *p = popen(command, "r");
    char line[512];
    double lo = -1, hi = -1;
    while (p && fgets(line, sizeof line, p))
        if (sscanf(line, " Stats Min: %lf", &lo) == 1 || sscanf(line, " Stats Max: %lf", &hi) == 1)
            continue;
    if (p)
        pclose(p);
    printf("adaptive: per-pixel samples from %g to %g\n", lo, hi);
    CHECK(lo >= 16 && lo < hi && hi == 64 && lo == floor(lo));

    CHECK_INT(test_ptr(LAMPS_SCENE, "-o", test_path("late.exr"), "--sample-range", "16:32",
                       "--noise-threshold", "0.05", "--quiet", NULL), usage);
    CHECK_INT(test_ptr("merge", whole, test_path("adaptive0.exr"), "-o", test_path("no.exr"),
                       "--quiet", NULL), usage);
    CHECK_INT(test_ptr(LAMPS_SCENE, "-o", test_path("plain.exr"), "--width", "80",
                       "--sample-range", "64:65", "--quiet", NULL), 0);
    CHECK_INT(test_ptr("merge", test_path("plain.exr"), test_path("adaptive-tiles.exr"), "-o",
                       test_path("no.exr"), "--quiet", NULL), usage);
}

static double worst_difference(const PtrImage *a, const PtrImage *b)
{
    double worst = 0;
    size_t n = (size_t)ptr_image_width(a) * ptr_image_height(a) * 3;
    for (size_t i = 0; i < n; i++) {
        double x = ptr_image_pixels(a)[i], y = ptr_image_pixels(b)[i];
        double rel = fabs(x - y) / fmax(fabs(y), 1e-3);
        worst = rel > worst ? rel : worst;
    }
    return worst;
}

/* Four sample ranges merged equal one render to within float rounding; four
 * regions merged equal it exactly. */
static void test_split_and_merge(void)
{
    const char *whole = test_path("whole.exr");
    CHECK_INT(test_ptr(FINAL_SCENE, "-o", whole, "--width", "80", "--samples", "16", "--quiet", NULL), 0);
    const char *ranges[] = { "0:4", "4:8", "8:12", "12:16" };
    for (int i = 0; i < 4; i++) {
        char name[32];
        snprintf(name, sizeof name, "range%d.exr", i);
        CHECK_INT(test_ptr(FINAL_SCENE, "-o", test_path(name), "--width", "80", "--sample-range",
                      ranges[i], "--quiet", NULL), 0);
    }
    CHECK_INT(test_ptr("merge", test_path("range2.exr"), test_path("range0.exr"), test_path("range3.exr"),
                  test_path("range1.exr"), "-o", test_path("merged.exr"), "--quiet", NULL), 0);
    PtrImage *a = load(whole), *b = load(test_path("merged.exr"));
    if (a && b) {
        CHECK_INT(ptr_image_width(b), 80);
        CHECK_STR(ptr_image_attr(b, "ptr:samples"), "16");
        CHECK_STR(ptr_image_attr(b, "ptr:sample_first"), "0");
        double worst = worst_difference(b, a);
        printf("4 sample ranges merged vs one render: worst relative difference %.2g\n", worst);
        CHECK(worst < 1e-6);
    }
    ptr_image_free(b);

    const char *regions[] = { "0,0,40,23", "40,0,80,23", "0,23,40,45", "40,23,80,45" };
    for (int i = 0; i < 4; i++) {
        char name[32];
        snprintf(name, sizeof name, "region%d.exr", i);
        CHECK_INT(test_ptr(FINAL_SCENE, "-o", test_path(name), "--width", "80", "--samples", "16",
                      "--region", regions[i], "--quiet", NULL), 0);
    }
    PtrImage *crop = load(test_path("region3.exr"));
    if (crop) {
        PtrImageLayout l = ptr_image_layout(crop);
        CHECK(l.width == 40 && l.height == 22 && l.x == 40 && l.y == 23 && l.full_width == 80 &&
              l.full_height == 45);
    }
    ptr_image_free(crop);
    CHECK_INT(test_ptr("merge", test_path("region0.exr"), test_path("region1.exr"), test_path("region2.exr"),
                  test_path("region3.exr"), "-o", test_path("tiles.exr"), "--quiet", NULL), 0);
    b = load(test_path("tiles.exr"));
    if (a && b)
        CHECK(!memcmp(ptr_image_pixels(a), ptr_image_pixels(b), 80 * 45 * 3 * sizeof(float)));
    ptr_image_free(a);
    ptr_image_free(b);
}

static void test_merge_refuses(void)
{
    const int usage = ptr_result_exit_code(PTR_ERR_USAGE);
    CHECK_INT(test_ptr(FINAL_SCENE, "-o", test_path("seed9.exr"), "--width", "80", "--sample-range", "0:4",
                  "--seed", "9", "--quiet", NULL), 0);
    CHECK_INT(test_ptr(SEED_SCENE, "-o", test_path("other.exr"), "--width", "80", "--height", "45",
                  "--sample-range", "4:8", "--quiet", NULL), 0);
    CHECK_INT(test_ptr(FINAL_SCENE, "-o", test_path("small.exr"), "--width", "40", "--sample-range", "4:8",
                  "--quiet", NULL), 0);
    CHECK_INT(test_ptr(FINAL_SCENE, "-o", test_path("range0.png"), "--width", "80", "--sample-range", "4:8",
                  "--quiet", NULL), 0);
    const char *out = test_path("refused.exr");
    CHECK_INT(test_ptr("merge", test_path("range0.exr"), test_path("seed9.exr"), "-o", out, NULL), usage);
    CHECK_INT(test_ptr("merge", test_path("range0.exr"), test_path("other.exr"), "-o", out, NULL), usage);
    CHECK_INT(test_ptr("merge", test_path("range1.exr"), test_path("small.exr"), "-o", out, NULL), usage);
    CHECK_INT(test_ptr("merge", test_path("range0.exr"), test_path("range0.exr"), "-o", out, NULL), usage);
    CHECK_INT(test_ptr("merge", test_path("region0.exr"), test_path("region1.exr"), "-o", out, NULL), usage);
    CHECK_INT(test_ptr("merge", test_path("range0.exr"), test_path("range0.png"), "-o", out, NULL), usage);
    CHECK_INT(test_ptr("merge", PTR_SOURCE_DIR "/README.md", "-o", out, NULL), usage);
    struct stat st;
    CHECK(stat(out, &st) != 0);
}

static void test_batch(void)
{
    mkdir(test_path("batch"), 0755);
    /* --json writes to stdout: catch it in a file. */
    fflush(stdout);
    int saved = dup(STDOUT_FILENO), json = open(test_path("batch.json"), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(json, STDOUT_FILENO);
    int code = test_ptr(SEED_SCENE, PTR_SOURCE_DIR "/tests/fixtures/bad/cycle.gltf", FINAL_SCENE, "-o",
                   test_path("batch/{name}-preview.png"), "--preview", "--json", "--quiet", NULL);
    fflush(stdout);
    dup2(saved, STDOUT_FILENO);
    close(saved);
    close(json);
    CHECK_INT(code, ptr_result_exit_code(PTR_ERR_BATCH));
    PtrImage *seed = load(test_path("batch/seed-preview.png")), *final = load(test_path("batch/final-preview.png"));
    if (seed && final) {
        CHECK_INT(ptr_image_width(seed), 125); /* a quarter of 500 */
        CHECK_INT(ptr_image_width(final), 100);
    }
    ptr_image_free(seed);
    ptr_image_free(final);
    FILE *f = fopen(test_path("batch.json"), "r");
    char line[4096];
    int lines = 0, errors = 0, previews = 0;
    while (f && fgets(line, sizeof line, f)) {
        lines++;
        errors += strstr(line, "\"status\": \"error\"") != NULL;
        previews += strstr(line, "\"samples\": 4,") != NULL;
    }
    if (f)
        fclose(f);
    CHECK_INT(lines, 3);
    CHECK_INT(errors, 1);
    CHECK_INT(previews, 2);

    /* Two scenes, one file: refused before anything renders. */
    CHECK_INT(test_ptr(SEED_SCENE, FINAL_SCENE, "-o", test_path("one.exr"), "--quiet", NULL),
              ptr_result_exit_code(PTR_ERR_USAGE));
}

/* A time budget stops early and says how many samples it took. */
static void test_time_budget(void)
{
    CHECK_INT(test_ptr(FINAL_SCENE, "-o", test_path("budget.exr"), "--samples", "1000000", "--time", "0.3",
                  "--width", "80", "--quiet", NULL), 0);
    PtrImage *img = load(test_path("budget.exr"));
    if (img) {
        long samples = atol(ptr_image_attr(img, "ptr:samples"));
        CHECK(samples >= 1 && samples < 1000000);
        CHECK_STR(ptr_image_attr(img, "ptr:interrupted"), "0");
    }
    ptr_image_free(img);
}

int main(void)
{
    if (!test_dir_create("test-split-renders"))
        return 1;
    const TestCase cases[] = {
        TEST_CASE(test_passes_are_exact),
        TEST_CASE(test_split_and_merge),
        TEST_CASE(test_merge_refuses),
        TEST_CASE(test_adaptive_parts),
        TEST_CASE(test_batch),
        TEST_CASE(test_time_budget),
    };
    TEST_RUN(cases);
    test_dir_remove();
    return test_report();
}
