/* Speed against accuracy. Renders a reference image of each benchmark scene
 * with many samples, then renders it again with 1, 2, 4, ... samples per
 * pixel and writes one CSV row per render: wall time and error against the
 * reference.
 *
 *   accuracy intersectors OUT.csv [MAX_SPP] [REFERENCE_SPP]
 *       every intersector this machine has (one estimator, seed 1)
 *   accuracy estimators OUT.csv [MAX_SPP] [REFERENCE_SPP] [SEEDS]
 *       the estimators (sampler, light sampling, adaptive sampling), with
 *       the fastest intersector; each point averages the squared error and
 *       the time over SEEDS seeds (default 4), since one seed's error
 *       wanders by tens of per cent at low sample counts
 *   accuracy denoise OUT.csv [MAX_SPP] [REFERENCE_SPP] [REFERENCE_DIR] [SCENE]
 *       the raw render against its denoised image at each quality (the
 *       default estimator, intersector and structure, as the CLI renders);
 *       a row's seconds are the render's and the denoiser's together, the
 *       denoiser's also apart; the reference, which takes minutes, is kept
 *       in REFERENCE_DIR (raw floats, read back when its size matches);
 *       SCENE (final or 1tii) runs one scene alone
 *
 * Errors: RMSE over all pixels and channels, and relative MSE, the mean of
 * (x - ref)^2 / (ref^2 + 0.01) (the 0.01 keeps dark pixels from dominating).
 * The reference uses the default estimator and another seed, so its own
 * noise is independent. */
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "base/cpu.h"
#include "denoise/denoise.h"
#include "importer.h"
#include "render/film.h"
#include "render/render.h"

typedef struct Bench {
    const char *name, *path;
    int width, height; /* reduced from the scenes' own sizes */
} Bench;

typedef struct Estimator {
    const char *name;
    PtrSamplerKind sampler;
    PtrSwitch direct_lighting;
    float noise_threshold;
} Estimator;

/* sobol+direct is the default; independent+direct is --sampler independent,
 * independent alone the estimator before either existed. */
static const Estimator estimators[] = {
    { "independent", PTR_SAMPLER_INDEPENDENT, PTR_OFF, 0 },
    { "sobol", PTR_SAMPLER_SOBOL, PTR_OFF, 0 },
    { "independent+direct", PTR_SAMPLER_INDEPENDENT, PTR_ON, 0 },
    { "sobol+direct", PTR_SAMPLER_SOBOL, PTR_ON, 0 },
    { "adaptive", PTR_SAMPLER_SOBOL, PTR_ON, 0.01f },
};

typedef struct Error {
    double se, rel; /* sums over pixels and channels */
} Error;

static int render(const PtrScene *scene, const PtrIsectTable *isect, PtrRenderSettings settings,
                  float *rgb, double *seconds)
{
    PtrRenderStats stats;
    PtrError err = { 0 };
    settings.max_depth = 50;
    settings.min_samples = 32;
    const PtrAccel accel = ptr_accel_brute(isect, scene);
    if (ptr_render(scene, &accel, &settings, rgb, &stats, &err) != PTR_OK) {
        fprintf(stderr, "accuracy: %s\n", err.message);
        return 0;
    }
    *seconds = stats.seconds;
    return 1;
}

static Error error_of(const float *img, const float *ref, size_t n)
{
    Error e = { 0, 0 };
    for (size_t i = 0; i < n; i++) {
        double d = (double)img[i] - ref[i];
        e.se += d * d;
        e.rel += d * d / ((double)ref[i] * ref[i] + 0.01);
    }
    return e;
}

static double fit_slope(const double *x, const double *y, int n)
{
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (int i = 0; i < n; i++)
        sx += x[i], sy += y[i], sxx += x[i] * x[i], sxy += x[i] * y[i];
    return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

/* A curve of the chart: an intersector and an estimator. */
typedef struct Method {
    const char *name;
    PtrIsectTable isect;
    PtrRenderSettings settings;
} Method;

/* A chart compares either the estimators or the CPU levels. */
#define ESTIMATOR_COUNT ((int)(sizeof estimators / sizeof estimators[0]))
enum {
    MAX_METHODS = ESTIMATOR_COUNT > PTR_CPU_LEVEL_COUNT ? ESTIMATOR_COUNT : PTR_CPU_LEVEL_COUNT,
    MAX_POINTS = 24,
};

/* Every method at spp = 1, 2, 4, ... max_spp, the errors and times averaged
 * over seeds 1 .. seeds. The methods take turns at each point, so that the
 * load of a shared machine weighs on all of them alike. */
static int curves(FILE *csv, const Bench *bench, const PtrScene *scene, const Method *methods,
                  int count, uint32_t max_spp, int seeds, const float *ref, float *img)
{
    size_t n = (size_t)bench->width * bench->height * 3;
    static double se[MAX_METHODS][MAX_POINTS], rel[MAX_METHODS][MAX_POINTS],
        seconds[MAX_METHODS][MAX_POINTS];
    memset(se, 0, sizeof se), memset(rel, 0, sizeof rel), memset(seconds, 0, sizeof seconds);
    int points = 0;
    for (uint32_t spp = 1; spp <= max_spp && points < MAX_POINTS; spp *= 2, points++)
        for (int s = 1; s <= seeds; s++)
            for (int m = 0; m < count; m++) {
                PtrRenderSettings settings = methods[m].settings;
                double t;
                settings.samples = spp;
                settings.seed = (uint64_t)s;
                if (!render(scene, &methods[m].isect, settings, img, &t))
                    return 0;
                Error e = error_of(img, ref, n);
                se[m][points] += e.se, rel[m][points] += e.rel, seconds[m][points] += t;
            }
    for (int m = 0; m < count; m++) {
        double x[MAX_POINTS], y[MAX_POINTS];
        for (int p = 0; p < points; p++) {
            double rmse = sqrt(se[m][p] / seeds / (double)n);
            fprintf(csv, "%s,%s,%u,%.6f,%.6g,%.6g\n", bench->name, methods[m].name, 1u << p,
                    seconds[m][p] / seeds, rmse, rel[m][p] / seeds / (double)n);
            x[p] = log((double)(1u << p)), y[p] = log(rmse);
        }
        fprintf(stderr, "%s: %-22s RMSE ~ spp^%.3f\n", bench->name, methods[m].name,
                fit_slope(x, y, points));
    }
    fflush(csv);
    return 1;
}

/* The denoiser's chart: raw renders against their denoised images. */
static const char *const quality_names[] = { "fast", "balanced", "high" };
enum { QUALITIES = 3 };

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* A render with the albedo and normal passes, as the CLI's --denoise
 * renders it; *seconds is the render's own. */
static int render_passes(const PtrScene *scene, const PtrAccel *accel, PtrRenderSettings settings,
                         float *rgb, float *albedo, float *normal, double *seconds)
{
    size_t pixels = (size_t)settings.width * settings.height;
    settings.passes = 1;
    settings.max_depth = 50;
    size_t stride = ptr_accum_stride(1);
    double *acc = ptr_accum_alloc(pixels, stride);
    PtrRenderStats stats;
    PtrError err = { 0 };
    if (!acc || ptr_render_samples(scene, accel, &settings, 0, settings.samples, acc, NULL, NULL,
                                   &stats, &err) != PTR_OK) {
        fprintf(stderr, "accuracy: %s\n", acc ? err.message : "out of memory");
        if (acc)
            ptr_accum_free(acc, pixels, stride);
        return 0;
    }
    ptr_accum_resolve(acc, pixels, stride, rgb, NULL, NULL);
    ptr_accum_resolve_passes(acc, pixels, albedo, normal);
    ptr_accum_free(acc, pixels, stride);
    *seconds = stats.seconds;
    return 1;
}

/* The reference of bench at spp samples into ref: read from dir if an
 * earlier run left it there, else rendered (seed 1000) and left there. */
static int reference(const Bench *bench, const PtrScene *scene, const PtrAccel *accel,
                     uint32_t spp, const char *dir, float *ref)
{
    size_t pixels = (size_t)bench->width * bench->height;
    char path[4096];
    snprintf(path, sizeof path, "%s/%s-%dx%d-%" PRIu32 "spp.f32", dir ? dir : ".", bench->name,
             bench->width, bench->height, spp);
    FILE *f = dir ? fopen(path, "rb") : NULL;
    size_t got = f ? fread(ref, sizeof *ref, pixels * 3, f) : 0;
    if (f)
        fclose(f);
    if (got == pixels * 3)
        return 1;
    float *albedo = malloc(pixels * 3 * sizeof *albedo), *normal = malloc(pixels * 3 * sizeof *normal);
    PtrRenderSettings settings = { .width = bench->width, .height = bench->height,
                                   .samples = spp, .seed = 1000 };
    double seconds;
    int ok = albedo && normal && render_passes(scene, accel, settings, ref, albedo, normal, &seconds);
    free(albedo);
    free(normal);
    if (!ok)
        return 0;
    fprintf(stderr, "%s: reference, %" PRIu32 " spp, %.1f s\n", bench->name, spp, seconds);
    if (dir && (f = fopen(path, "wb"))) {
        fwrite(ref, sizeof *ref, pixels * 3, f);
        fclose(f);
    }
    return 1;
}

/* Rows of bench at spp = 1, 2, 4, ... max_spp: raw, then denoised at each
 * quality. */
static int denoise_curves(FILE *csv, const Bench *bench, const PtrScene *scene,
                          const PtrAccel *accel, PtrDenoiser *const *denoisers, uint32_t max_spp,
                          const float *ref)
{
    size_t pixels = (size_t)bench->width * bench->height, n = pixels * 3;
    float *rgb = malloc(n * sizeof *rgb), *albedo = malloc(n * sizeof *albedo),
          *normal = malloc(n * sizeof *normal), *out = malloc(n * sizeof *out);
    int ok = rgb && albedo && normal && out;
    for (uint32_t spp = 1; ok && spp <= max_spp; spp *= 2) {
        PtrRenderSettings settings = { .width = bench->width, .height = bench->height,
                                       .samples = spp, .seed = 1 };
        double render_seconds;
        ok = render_passes(scene, accel, settings, rgb, albedo, normal, &render_seconds);
        for (int q = -1; ok && q < QUALITIES; q++) {
            double denoise_seconds = 0;
            const float *img = rgb;
            if (q >= 0) {
                const PtrDenoiseInput input = {
                    .color = rgb, .albedo = albedo, .normal = normal,
                    .color_stride = 3, .albedo_stride = 3, .normal_stride = 3,
                    .width = (size_t)bench->width, .height = (size_t)bench->height,
                };
                PtrError err = { 0 };
                double start = now();
                ok = ptr_denoise(denoisers[q], &input, ptr_usable_cpus(), out, 3, &err) == PTR_OK;
                denoise_seconds = now() - start;
                if (!ok)
                    fprintf(stderr, "accuracy: %s\n", err.message);
                img = out;
            }
            Error e = error_of(img, ref, n);
            fprintf(csv, "%s,%s,%u,%.6f,%.6g,%.6g,%.6f\n", bench->name,
                    q < 0 ? "raw" : quality_names[q], spp, render_seconds + denoise_seconds,
                    sqrt(e.se / (double)n), e.rel / (double)n, denoise_seconds);
        }
        fflush(csv);
    }
    free(rgb), free(albedo), free(normal), free(out);
    return ok;
}

/* final.gltf and the molecule, at sizes whose 16,384-spp references take
 * about 2 CPU-minutes each (8 minutes on 2 cores shared with heavy other
 * work). */
static int denoise_chart(FILE *csv, uint32_t max_spp, uint32_t ref_spp, const char *dir,
                         const char *only)
{
    static const Bench benches[] = {
        { "final", PTR_SOURCE_DIR "/scenes/final.gltf", 160, 90 },
        { "1tii", PTR_SOURCE_DIR "/scenes/1tii.pdb", 96, 72 },
    };
    PtrDenoiser *denoisers[QUALITIES] = { 0 };
    PtrError err = { 0 };
    for (int q = 0; q < QUALITIES; q++)
        if (ptr_denoiser_new((PtrDenoiseQuality)q, NULL, ptr_cpu_level(), &denoisers[q], &err) !=
            PTR_OK) {
            fprintf(stderr, "accuracy: %s\n", err.message);
            return 0;
        }
    fprintf(csv, "scene,method,spp,seconds,rmse,relmse,denoise_seconds\n");
    int ok = 1;
    for (size_t b = 0; ok && b < sizeof benches / sizeof benches[0]; b++) {
        const Bench *bench = &benches[b];
        if (only && strcmp(only, bench->name))
            continue;
        PtrScene scene;
        PtrStrings warnings = { 0 };
        if (ptr_import_scene(bench->path, NULL, &scene, &warnings, &err) != PTR_OK) {
            fprintf(stderr, "accuracy: %s\n", err.message);
            ok = 0;
            break;
        }
        ptr_strings_free(&warnings);
        PtrIsectTable isect;
        ptr_isect_init(&isect, PTR_KERNEL_AUTO, ptr_cpu_level(), scene.spheres.count, NULL);
        PtrRenderSettings defaults = { 0 };
        PtrAccel accel;
        ok = ptr_accel_init(&accel, PTR_ACCEL_AUTO, &isect,
                            ptr_render_integrator(&defaults) == PTR_INTEGRATOR_BUNDLES, &scene, 0,
                            &err) == PTR_OK;
        float *ref = malloc((size_t)bench->width * bench->height * 3 * sizeof *ref);
        ok = ok && ref && reference(bench, &scene, &accel, ref_spp, dir, ref) &&
             denoise_curves(csv, bench, &scene, &accel, denoisers, max_spp, ref);
        free(ref);
        ptr_accel_free(&accel);
        ptr_scene_free(&scene);
    }
    for (int q = 0; q < QUALITIES; q++)
        ptr_denoiser_free(denoisers[q]);
    return ok;
}

int main(int argc, char **argv)
{
    int by_estimator = argc > 2 && !strcmp(argv[1], "estimators");
    int denoised = argc > 2 && !strcmp(argv[1], "denoise");
    if (argc < 3 || (!by_estimator && !denoised && strcmp(argv[1], "intersectors"))) {
        fprintf(stderr, "usage: accuracy intersectors|estimators OUT.csv [MAX_SPP] [REFERENCE_SPP]"
                        " [SEEDS]\n       accuracy denoise OUT.csv [MAX_SPP] [REFERENCE_SPP]"
                        " [REFERENCE_DIR] [SCENE]\n");
        return 2;
    }
    uint32_t max_spp = argc > 3 ? (uint32_t)atoi(argv[3]) : 256;
    uint32_t ref_spp = argc > 4 ? (uint32_t)atoi(argv[4]) : 4096;
    if (denoised) {
        FILE *csv = fopen(argv[2], "w");
        if (!csv) {
            perror(argv[2]);
            return 1;
        }
        int ok = denoise_chart(csv, max_spp, ref_spp, argc > 5 ? argv[5] : NULL,
                               argc > 6 ? argv[6] : NULL);
        fclose(csv);
        return ok ? 0 : 1;
    }
    int seeds = by_estimator && argc > 5 ? atoi(argv[5]) : by_estimator ? 4 : 1;
    static const Bench intersector_benches[] = {
        { "seed", PTR_SOURCE_DIR "/scenes/seed.gltf", 125, 125 },
        { "final", PTR_SOURCE_DIR "/scenes/final.gltf", 200, 112 },
    };
    static const Bench estimator_benches[] = {
        { "final", PTR_SOURCE_DIR "/scenes/final.gltf", 200, 112 },
        { "lamps", PTR_SOURCE_DIR "/scenes/lamps.gltf", 200, 112 },
    };
    const Bench *benches = by_estimator ? estimator_benches : intersector_benches;
    FILE *csv = fopen(argv[2], "w");
    if (!csv) {
        perror(argv[2]);
        return 1;
    }
    fprintf(csv, "scene,method,spp,seconds,rmse,relmse\n");

    for (size_t b = 0; b < 2; b++) {
        const Bench *bench = &benches[b];
        PtrScene scene;
        PtrStrings warnings = { 0 };
        PtrError err = { 0 };
        if (ptr_import_scene(bench->path, NULL, &scene, &warnings, &err) != PTR_OK) {
            fprintf(stderr, "accuracy: %s\n", err.message);
            return 1;
        }
        ptr_strings_free(&warnings);
        size_t n = (size_t)bench->width * bench->height * 3;
        float *ref = malloc(n * sizeof *ref), *img = malloc(n * sizeof *img);
        PtrIsectTable fastest;
        ptr_isect_init(&fastest, PTR_KERNEL_AUTO, ptr_cpu_level(), scene.spheres.count, NULL);
        PtrRenderSettings settings = { .width = bench->width, .height = bench->height,
                                       .samples = ref_spp, .seed = 1000 };
        double seconds;
        if (!render(&scene, &fastest, settings, ref, &seconds))
            return 1;
        fprintf(stderr, "%s: reference, %" PRIu32 " spp, %.1f s\n", bench->name, ref_spp, seconds);

        Method methods[MAX_METHODS];
        int count = 0;
        for (int e = 0; by_estimator && e < ESTIMATOR_COUNT; e++) {
            const Estimator *est = &estimators[e];
            Method *m = &methods[count++];
            *m = (Method){ est->name, fastest, settings };
            m->settings.sampler = est->sampler;
            m->settings.direct_lighting = est->direct_lighting;
            m->settings.noise_threshold = est->noise_threshold;
        }
        for (int l = PTR_CPU_NONE; !by_estimator && l <= (int)ptr_cpu_level(); l++) {
            if (l > PTR_CPU_NONE && !ptr_isect_has_asm())
                break;
            Method *m = &methods[count++];
            *m = (Method){ NULL, { 0 }, settings };
            ptr_isect_init_level(&m->isect, (PtrCpuLevel)l);
            m->name = m->isect.name;
            m->settings.sampler = PTR_SAMPLER_INDEPENDENT;
            m->settings.direct_lighting = PTR_OFF;
        }
        if (!curves(csv, bench, &scene, methods, count, max_spp, seeds, ref, img))
            return 1;
        free(ref);
        free(img);
        ptr_scene_free(&scene);
    }
    fclose(csv);
    return 0;
}
