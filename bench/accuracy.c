/* Speed against accuracy: renders a reference image of each benchmark scene
 * with many samples, then renders it again with 1, 2, 4, ... samples per
 * pixel with every intersector this machine has, and writes one CSV row per
 * render: wall time and error against the reference.
 *
 *   accuracy OUT.csv [MAX_SPP] [REFERENCE_SPP]
 *
 * Errors: RMSE over all pixels and channels, and relative MSE, the mean of
 * (x - ref)^2 / (ref^2 + 0.01) (the 0.01 keeps dark pixels from dominating).
 * The reference uses another seed, so its own noise is independent. */
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "accel/cpu.h"
#include "importer.h"
#include "core/render.h"

typedef struct Bench {
    const char *name, *path;
    int width, height; /* reduced from the scenes' own sizes */
} Bench;

static int render(const PtrScene *scene, const PtrIsectTable *isect, int w, int h,
                  uint32_t spp, uint64_t seed, float *rgb, double *seconds)
{
    PtrRenderSettings settings = { .width = w, .height = h, .samples = spp, .seed = seed,
                                   .max_depth = 50 };
    PtrRenderStats stats;
    PtrError err = { 0 };
    const PtrAccel accel = ptr_accel_brute(isect, scene);
    if (ptr_render(scene, &accel, &settings, rgb, &stats, &err) != PTR_OK) {
        fprintf(stderr, "accuracy: %s\n", err.message);
        return 0;
    }
    *seconds = stats.seconds;
    return 1;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: accuracy OUT.csv [MAX_SPP] [REFERENCE_SPP]\n");
        return 2;
    }
    uint32_t max_spp = argc > 2 ? (uint32_t)atoi(argv[2]) : 256;
    uint32_t ref_spp = argc > 3 ? (uint32_t)atoi(argv[3]) : 4096;
    static const Bench benches[] = {
        { "seed", PTR_SOURCE_DIR "/scenes/seed.gltf", 125, 125 },
        { "final", PTR_SOURCE_DIR "/scenes/final.gltf", 200, 112 },
    };
    FILE *csv = fopen(argv[1], "w");
    if (!csv) {
        perror(argv[1]);
        return 1;
    }
    fprintf(csv, "scene,method,spp,seconds,rmse,relmse\n");

    for (size_t b = 0; b < sizeof benches / sizeof benches[0]; b++) {
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
        ptr_isect_init(&fastest, PTR_KERNEL_AUTO, scene.spheres.count);
        double seconds;
        if (!render(&scene, &fastest, bench->width, bench->height, ref_spp, 1000, ref, &seconds))
            return 1;
        fprintf(stderr, "%s: reference, %" PRIu32 " spp, %.1f s\n", bench->name, ref_spp, seconds);

        for (int l = PTR_CPU_NONE; l <= (int)ptr_cpu_level(); l++) {
            PtrIsectTable isect;
            ptr_isect_init_level(&isect, (PtrCpuLevel)l);
            if (l > PTR_CPU_NONE && !ptr_isect_has_asm())
                break;
            double sx = 0, sy = 0, sxx = 0, sxy = 0;
            int points = 0;
            for (uint32_t spp = 1; spp <= max_spp; spp *= 2) {
                if (!render(&scene, &isect, bench->width, bench->height, spp, 1, img, &seconds))
                    return 1;
                double se = 0, rel = 0;
                for (size_t i = 0; i < n; i++) {
                    double d = (double)img[i] - ref[i];
                    se += d * d;
                    rel += d * d / ((double)ref[i] * ref[i] + 0.01);
                }
                double rmse = sqrt(se / (double)n);
                fprintf(csv, "%s,%s,%" PRIu32 ",%.6f,%.6g,%.6g\n", bench->name, isect.name, spp,
                        seconds, rmse, rel / (double)n);
                double x = log((double)spp), y = log(rmse);
                sx += x, sy += y, sxx += x * x, sxy += x * y, points++;
            }
            double slope = (points * sxy - sx * sy) / (points * sxx - sx * sx);
            fprintf(stderr, "%s: %-6s RMSE ~ spp^%.3f\n", bench->name, isect.name, slope);
        }
        free(ref);
        free(img);
        ptr_scene_free(&scene);
    }
    fclose(csv);
    return 0;
}
