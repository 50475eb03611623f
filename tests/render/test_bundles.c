/* Every integrator with every kernel against paths one at a time with the C
 * kernels (render.c's trace_path, the reference): bundles of paths
 * (render/bundle.c) with the C kernels and with the fastest, and paths one
 * at a time with the fastest. The same sums for every pixel, bit for bit,
 * and the same number of rays, on scenes that take every branch a path can
 * take (each material, fuzz, colours, emitters with light sampling, a huge
 * sphere, the tree, no sphere at all, an orthographic camera) under every
 * setting that changes a path (sampler, light sampling, depth limit,
 * adaptive sampling, regions, sample ranges split into passes, threads),
 * with the albedo and normal passes' sums too where they are asked for.
 * Below AVX2 there are no bundles, which the test says. */
#include "test.h"

#include "accel/accel.h"
#include "base/cpu.h"
#include "builder.h"
#include "render/render.h"
#include "sampling/rng.h"

enum { WIDTH = 48, HEIGHT = 32 };

typedef enum SceneKind { CLUSTER, ORTHOGRAPHIC, HUGE_GROUND, CLOUD, EMPTY } SceneKind;
static const char *const scene_names[] = { "cluster", "cluster, orthographic", "huge ground",
                                           "cloud", "empty" };

static uint32_t add(PtrScene *s, PtrMaterial m)
{
    uint32_t index = 0;
    CHECK_INT(ptr_scene_add_material(s, &m, &index, NULL), PTR_OK);
    return index;
}

/* Spheres of every material (some coloured, some emitting, glass inside
 * glass, overlaps) over a ground, seen through a lens, or orthographically
 * (parallel rays from a near plane that stays clear of every sphere). */
static PtrScene make_scene(SceneKind kind)
{
    PtrScene s;
    ptr_scene_init(&s);
    uint32_t materials[6] = {
        add(&s, (PtrMaterial){ .kind = PTR_MATERIAL_DIFFUSE, .albedo = v3(0.7f, 0.6f, 0.5f) }),
        add(&s, (PtrMaterial){ .kind = PTR_MATERIAL_METAL, .albedo = v3(0.8f, 0.8f, 0.9f) }),
        add(&s, (PtrMaterial){ .kind = PTR_MATERIAL_METAL, .albedo = v3(0.9f, 0.6f, 0.3f),
                               .fuzz = 0.3f }),
        add(&s, (PtrMaterial){ .kind = PTR_MATERIAL_DIELECTRIC, .albedo = v3_splat(1.0f),
                               .ior = 1.5f }),
        add(&s, (PtrMaterial){ .kind = PTR_MATERIAL_DIFFUSE, .albedo = v3_splat(0.0f),
                               .emission = v3(4.0f, 3.0f, 2.0f) }),
        add(&s, (PtrMaterial){ .kind = PTR_MATERIAL_DIELECTRIC, .albedo = v3(0.9f, 1.0f, 0.9f),
                               .ior = 1.0f / 1.5f }),
    };
    PtrSceneBuilder b;
    ptr_builder_init(&b, &s, NULL);
    PtrRng rng = ptr_rng_for_sample(kind, 7, 0);
    int n = kind == CLUSTER || kind == ORTHOGRAPHIC ? 60
            : kind == CLOUD                        ? 3000
            : kind == HUGE_GROUND                  ? 12
                                                   : 0;
    for (int i = 0; i < n; i++) {
        double spread = kind == CLOUD ? 12.0 : 4.0;
        double c[3] = { spread * (ptr_rng_float(&rng) - 0.5), 1.5 * ptr_rng_float(&rng),
                        spread * (ptr_rng_float(&rng) - 0.5) };
        double r = (kind == CLOUD ? 0.08 : 0.2) + 0.4 * ptr_rng_float(&rng);
        CHECK_INT(ptr_builder_add_sphere(&b, c, r, materials[i % 6], NULL), PTR_OK);
        if (i % 5 == 1) {
            const double rgb[3] = { ptr_rng_float(&rng), ptr_rng_float(&rng), ptr_rng_float(&rng) };
            CHECK_INT(ptr_builder_set_color(&b, rgb, NULL), PTR_OK);
        }
        if (i % 9 == 3) /* glass inside glass */
            CHECK_INT(ptr_builder_add_sphere(&b, c, 0.5 * r, materials[3], NULL), PTR_OK);
    }
    if (kind != EMPTY) {
        double radius = kind == HUGE_GROUND ? 1e5 : 100.0;
        const double ground[3] = { 0, -radius, 0 };
        CHECK_INT(ptr_builder_add_sphere(&b, ground, radius, materials[0], NULL), PTR_OK);
    }
    const double eye[3] = { 0, 2, 7 }, target[3] = { 0, 0.5, 0 }, up[3] = { 0, 1, 0 };
    const PtrCamera lens = kind == ORTHOGRAPHIC
                               ? (PtrCamera){ .projection = PTR_PROJECTION_ORTHOGRAPHIC,
                                              .ymag = 1.5f, .znear = 1.0f }
                               : (PtrCamera){ .vfov_deg = 50.0f, .aperture = 0.1f,
                                              .focus_distance = 7.0f };
    ptr_builder_set_camera(&b, eye, target, up, &lens);
    CHECK_INT(ptr_builder_finish(&b, PTR_BUILD_DEFAULT, NULL), PTR_OK);
    s.sky = kind == HUGE_GROUND ? (PtrSky){ PTR_SKY_CONSTANT, v3(0.3f, 0.4f, 0.5f) }
                                : (PtrSky){ PTR_SKY_GRADIENT, v3_splat(0.0f) };
    return s;
}

typedef struct Sums {
    double *acc;
    uint64_t rays;
} Sums;

/* Samples [first, first + count) of the region in passes of pass samples. */
static Sums render(PtrScene *scene, PtrKernel kernel, PtrIntegrator integrator,
                   PtrRenderSettings settings, uint32_t first, uint32_t count, uint32_t pass)
{
    settings.integrator = integrator;
    PtrIsectTable isect;
    PtrAccel accel;
    PtrError err = { 0 };
    PtrRegion r = ptr_render_region(&settings);
    size_t pixels = (size_t)(r.x1 - r.x0) * (size_t)(r.y1 - r.y0);
    Sums sums = { calloc(pixels * ptr_accum_stride(settings.passes), sizeof(double)), 0 };
    CHECK_INT(ptr_isect_init(&isect, kernel, ptr_cpu_level(), scene->spheres.count, NULL), PTR_OK);
    CHECK_INT(ptr_accel_init(&accel, PTR_ACCEL_AUTO, &isect, integrator == PTR_INTEGRATOR_BUNDLES,
                             scene, 0, NULL),
              PTR_OK);
    for (uint32_t done = 0; done < count; done += pass) {
        PtrRenderStats stats;
        uint32_t n = count - done < pass ? count - done : pass;
        CHECK_INT(ptr_render_samples(scene, &accel, &settings, first + done, n, sums.acc, NULL,
                                     NULL, &stats, &err),
                  PTR_OK);
        sums.rays += stats.rays;
    }
    ptr_accel_free(&accel);
    return sums;
}

/* Frees b's sums (stride doubles a pixel), which must be a's. */
static int compare(const char *what, Sums a, Sums b, size_t pixels, size_t stride)
{
    size_t differ = 0;
    for (size_t i = 0; i < pixels * stride; i++)
        differ += memcmp(&a.acc[i], &b.acc[i], sizeof(double)) != 0;
    if (differ || a.rays != b.rays)
        fprintf(stderr, "%s: %zu sums differ, rays %llu against %llu\n", what, differ,
                (unsigned long long)a.rays, (unsigned long long)b.rays);
    CHECK_INT(differ, 0);
    CHECK_INT(a.rays, b.rays);
    free(b.acc);
    return differ == 0;
}

typedef struct Pair {
    PtrIntegrator integrator;
    PtrKernel kernel;
    const char *name;
} Pair;

static const Pair pairs[] = {
    { PTR_INTEGRATOR_PATHS, PTR_KERNEL_AUTO, "paths, fastest kernel" },
    { PTR_INTEGRATOR_BUNDLES, PTR_KERNEL_C, "bundles, C kernels" },
    { PTR_INTEGRATOR_BUNDLES, PTR_KERNEL_AUTO, "bundles, fastest kernel" },
};

typedef struct Variant {
    const char *name;
    PtrRenderSettings settings;
    uint32_t first, count, pass;
} Variant;

/* Every setting that changes a path, each on the base settings. */
static Variant variants[] = {
    { "default", { 0 }, 0, 12, 12 },
    { "independent sampler, no light sampling", { 0 }, 0, 9, 9 },
    { "depth 0", { 0 }, 0, 3, 3 },
    { "depth 1", { 0 }, 0, 5, 5 },
    { "depth 3", { 0 }, 0, 5, 5 },
    { "adaptive", { 0 }, 0, 48, 48 },
    { "region, samples 7..26 in passes of 5, one thread", { 0 }, 7, 19, 5 },
    { "transparent, in passes of 4", { 0 }, 0, 12, 4 },
    { "transparent, adaptive", { 0 }, 0, 48, 48 },
    /* The albedo and normal passes on the settings of variants above
     * (with_passes). */
    { "passes", { 0 }, 0, 12, 12 },
    { "passes, depth 0", { 0 }, 0, 3, 3 },
    { "passes, depth 3", { 0 }, 0, 5, 5 },
    { "passes, region, samples 7..26 in passes of 5, one thread", { 0 }, 7, 19, 5 },
    { "passes, transparent, in passes of 4", { 0 }, 0, 12, 4 },
    { "passes, transparent, adaptive", { 0 }, 0, 48, 48 },
};
static const int with_passes[] = { 0, 2, 4, 6, 7, 8 };
enum { VARIANTS = sizeof variants / sizeof variants[0] };

static void set_variants(void)
{
    const PtrRenderSettings base = { .width = WIDTH, .height = HEIGHT, .seed = 5, .max_depth = 50,
                                     .threads = 2 };
    for (int v = 0; v < VARIANTS; v++)
        variants[v].settings = base;
    variants[1].settings.sampler = PTR_SAMPLER_INDEPENDENT;
    variants[1].settings.direct_lighting = PTR_OFF;
    variants[2].settings.max_depth = 0;
    variants[3].settings.max_depth = 1;
    variants[4].settings.max_depth = 3;
    variants[5].settings.noise_threshold = 0.05f;
    variants[5].settings.min_samples = 16;
    variants[6].settings.region = (PtrRegion){ 5, 3, 37, 29 };
    variants[6].settings.threads = 1;
    variants[7].settings.transparent = 1;
    variants[8].settings.transparent = 1;
    variants[8].settings.noise_threshold = 0.05f;
    variants[8].settings.min_samples = 16;
    enum { FIRST_WITH_PASSES = VARIANTS - sizeof with_passes / sizeof with_passes[0] };
    for (int v = FIRST_WITH_PASSES; v < VARIANTS; v++) {
        variants[v].settings = variants[with_passes[v - FIRST_WITH_PASSES]].settings;
        variants[v].settings.passes = 1;
    }
}

/* Every variant of one scene, every pair against the reference. */
static void test_scene(SceneKind kind)
{
    const int bundles = ptr_integrator_available(PTR_INTEGRATOR_BUNDLES, ptr_cpu_level());
    /* A scene of its own for each side, as every render builds over it
     * again: each cluster goes to the tree with the C kernels (68 spheres,
     * above their crossover) and to brute force with assembly, which
     * searches the spheres in the build's order too. */
    PtrScene scene = make_scene(kind), other = make_scene(kind);
    for (int v = 0; v < VARIANTS; v++) {
        const Variant *var = &variants[v];
        PtrRegion r = ptr_render_region(&var->settings);
        size_t pixels = (size_t)(r.x1 - r.x0) * (size_t)(r.y1 - r.y0);
        Sums reference = render(&scene, PTR_KERNEL_C, PTR_INTEGRATOR_PATHS, var->settings,
                                var->first, var->count, var->count);
        for (size_t p = 0; p < sizeof pairs / sizeof pairs[0]; p++) {
            if (pairs[p].integrator == PTR_INTEGRATOR_BUNDLES && !bundles)
                continue;
            Sums other_sums = render(&other, pairs[p].kernel, pairs[p].integrator,
                                     var->settings, var->first, var->count, var->pass);
            char what[200];
            snprintf(what, sizeof what, "%s, %s: %s", scene_names[kind], var->name,
                     pairs[p].name);
            if (compare(what, reference, other_sums, pixels,
                        ptr_accum_stride(var->settings.passes)))
                printf("  %-90s identical\n", what);
        }
        free(reference.acc);
    }
    ptr_scene_free(&scene);
    ptr_scene_free(&other);
}

static void test_cluster(void)
{
    test_scene(CLUSTER);
}

static void test_orthographic(void)
{
    test_scene(ORTHOGRAPHIC);
}

static void test_huge_ground(void)
{
    test_scene(HUGE_GROUND);
}

static void test_cloud(void)
{
    test_scene(CLOUD);
}

static void test_empty(void)
{
    test_scene(EMPTY);
}

int main(void)
{
    printf("test_bundles: against paths with the C kernels: %s\n",
           ptr_integrator_available(PTR_INTEGRATOR_BUNDLES, ptr_cpu_level())
               ? "paths with the fastest kernel, bundles with C and the fastest"
               : "paths with the fastest kernel (no bundles at this CPU level)");
    set_variants();
    const TestCase cases[] = {
        TEST_CASE(test_cluster),    TEST_CASE(test_orthographic), TEST_CASE(test_huge_ground),
        TEST_CASE(test_cloud),      TEST_CASE(test_empty),
    };
    TEST_RUN(cases);
    return test_report();
}
