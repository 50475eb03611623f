/* The bias of adaptive sampling. A pixel stops when its own samples look
 * converged, and samples that happen to agree are more likely to stop it
 * early, so its expected value is not quite the pixel's. This renders each
 * scene SEEDS times with and without --noise-threshold and compares, against
 * a reference:
 *
 *   - the mean signed error of the whole image's mean, as a share of it;
 *   - the RMSE of the average over seeds: noise falls as 1/sqrt(SEEDS), bias
 *     does not, so a gap between the two estimators is the bias;
 *   - samples per pixel actually taken, and the time.
 *
 *   adaptive_bias [SPP] [SEEDS] [THRESHOLD] [REFERENCE_SPP] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "importer.h"
#include "render/render.h"

enum { WIDTH = 200, HEIGHT = 112, PIXELS = WIDTH * HEIGHT };

static int render(const PtrScene *scene, const PtrIsectTable *isect, PtrRenderSettings s,
                  float *rgb, float *counts, double *seconds)
{
    static double acc[PIXELS * PTR_ACCUM_STRIDE];
    PtrRenderStats stats;
    PtrError err = { 0 };
    for (size_t i = 0; i < sizeof acc / sizeof acc[0]; i++)
        acc[i] = 0;
    const PtrAccel accel = ptr_accel_brute(isect, scene);
    if (ptr_render_samples(scene, &accel, &s, 0, s.samples, acc, NULL, NULL, &stats, &err) != PTR_OK) {
        fprintf(stderr, "adaptive_bias: %s\n", err.message);
        return 0;
    }
    ptr_accum_resolve(acc, PIXELS, PTR_ACCUM_STRIDE, rgb, NULL, counts);
    *seconds += stats.seconds;
    return 1;
}

int main(int argc, char **argv)
{
    uint32_t spp = argc > 1 ? (uint32_t)atoi(argv[1]) : 256;
    int seeds = argc > 2 ? atoi(argv[2]) : 16;
    float threshold = argc > 3 ? (float)atof(argv[3]) : 0.01f;
    uint32_t ref_spp = argc > 4 ? (uint32_t)atoi(argv[4]) : 4096;
    static const char *const scenes[] = { PTR_SOURCE_DIR "/scenes/final.gltf",
                                          PTR_SOURCE_DIR "/scenes/lamps.gltf" };
    static float ref[PIXELS * 3], img[PIXELS * 3], counts[PIXELS];
    static double mean[2][PIXELS * 3];
    printf("%u spp, %d seeds, threshold %g, %u-spp reference\n", spp, seeds, threshold, ref_spp);
    printf("%-6s %-9s %10s %12s %12s %9s %9s\n", "scene", "method", "mean err", "RMSE 1 seed",
           "RMSE mean", "spp used", "seconds");
    for (int k = 0; k < 2; k++) {
        PtrScene scene;
        PtrStrings warnings = { 0 };
        PtrError err = { 0 };
        if (ptr_import_scene(scenes[k], NULL, &scene, &warnings, &err) != PTR_OK) {
            fprintf(stderr, "adaptive_bias: %s\n", err.message);
            return 1;
        }
        ptr_strings_free(&warnings);
        PtrIsectTable isect;
        ptr_isect_init(&isect, PTR_KERNEL_AUTO, ptr_cpu_level(), scene.spheres.count, NULL);
        PtrRenderSettings s = { .width = WIDTH, .height = HEIGHT, .samples = ref_spp, .seed = 1000,
                                .max_depth = 50, .min_samples = 32 };
        double t = 0, ref_sum = 0;
        if (!render(&scene, &isect, s, ref, counts, &t))
            return 1;
        for (int i = 0; i < PIXELS * 3; i++)
            ref_sum += ref[i];
        double se1[2] = { 0 }, used[2] = { 0 }, seconds[2] = { 0 };
        for (int m = 0; m < 2; m++)
            for (int i = 0; i < PIXELS * 3; i++)
                mean[m][i] = 0;
        s.samples = spp;
        for (int seed = 1; seed <= seeds; seed++)
            for (int m = 0; m < 2; m++) {
                s.seed = (uint64_t)seed;
                s.noise_threshold = m ? threshold : 0;
                if (!render(&scene, &isect, s, img, counts, &seconds[m]))
                    return 1;
                for (int i = 0; i < PIXELS * 3; i++) {
                    double d = (double)img[i] - ref[i];
                    se1[m] += d * d;
                    mean[m][i] += img[i] / (double)seeds;
                }
                for (int p = 0; p < PIXELS; p++)
                    used[m] += counts[p] / ((double)PIXELS * seeds);
            }
        for (int m = 0; m < 2; m++) {
            double sum = 0, se = 0;
            for (int i = 0; i < PIXELS * 3; i++) {
                sum += mean[m][i];
                se += (mean[m][i] - ref[i]) * (mean[m][i] - ref[i]);
            }
            printf("%-6s %-9s %+9.3f%% %12.5f %12.5f %9.1f %9.2f\n", k ? "lamps" : "final",
                   m ? "adaptive" : "fixed", 100 * (sum - ref_sum) / ref_sum,
                   sqrt(se1[m] / seeds / (PIXELS * 3)), sqrt(se / (PIXELS * 3)), used[m],
                   seconds[m] / seeds);
        }
        ptr_scene_free(&scene);
    }
    return 0;
}
