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

#include "base/cpu.h"
#include "importer.h"
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

int main(int argc, char **argv)
{
    int by_estimator = argc > 2 && !strcmp(argv[1], "estimators");
    if (argc < 3 || (!by_estimator && strcmp(argv[1], "intersectors"))) {
        fprintf(stderr, "usage: accuracy intersectors|estimators OUT.csv [MAX_SPP] [REFERENCE_SPP]"
                        " [SEEDS]\n");
        return 2;
    }
    uint32_t max_spp = argc > 3 ? (uint32_t)atoi(argv[3]) : 256;
    uint32_t ref_spp = argc > 4 ? (uint32_t)atoi(argv[4]) : 4096;
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
