/* The path tracer's speed by method, in one run: paths one at a time (the C
 * reference, as `ptr --c` renders; and with the SSE4.1 kernel, as an SSE4.1
 * CPU renders) against bundles of paths (AVX2, with the C kernels and with
 * the fastest), on 1 and 2 threads, the
 * configurations taking turns run after run. No image is written, so the
 * image library's load (on a thread of its own in `ptr`) does not share the
 * cores with the render.
 *
 *   paths SCENE [WIDTH HEIGHT SPP [RUNS]]      (defaults: 400 225 20, 3 runs)
 *
 * Prints each run's Mrays/s (camera, scattered and shadow rays over render
 * seconds), then per configuration the best run and its ratio to paths one
 * at a time on one thread, and each configuration's 2-thread over 1-thread
 * speed-up. Every render must give the first one's pixels bit for bit:
 * otherwise it says which differ and exits 1. */
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "accel/accel.h"
#include "base/cpu.h"
#include "bench_args.h"
#include "importer.h"
#include "render/render.h"

typedef struct Config {
    const char *name;
    PtrIntegrator integrator;
    PtrKernel kernel;
    PtrCpuLevel cap;
} Config;

static const Config configs[] = {
    { "paths one at a time (c)", PTR_INTEGRATOR_PATHS, PTR_KERNEL_C, PTR_CPU_NONE },
    { "paths one at a time (sse41)", PTR_INTEGRATOR_PATHS, PTR_KERNEL_AUTO, PTR_CPU_SSE41 },
    { "bundles, c kernels", PTR_INTEGRATOR_BUNDLES, PTR_KERNEL_C, PTR_CPU_AVX2 },
    { "bundles, avx2", PTR_INTEGRATOR_BUNDLES, PTR_KERNEL_AUTO, PTR_CPU_AVX2 },
};
enum { CONFIGS = sizeof configs / sizeof configs[0], MAX_THREADS = 2 };

static double render(PtrScene *scene, const Config *c, PtrRenderSettings settings, float *rgb)
{
    settings.integrator = c->integrator;
    PtrIsectTable isect;
    PtrAccel accel;
    PtrRenderStats stats;
    PtrError err = { 0 };
    ptr_isect_init(&isect, c->kernel, c->cap, scene->spheres.count, NULL);
    if (ptr_accel_init(&accel, PTR_ACCEL_AUTO, &isect, c->integrator == PTR_INTEGRATOR_BUNDLES,
                       scene, 0, NULL) != PTR_OK ||
        ptr_render(scene, &accel, &settings, rgb, &stats, &err) != PTR_OK) {
        fprintf(stderr, "paths: %s\n", err.message[0] ? err.message : "out of memory");
        exit(2);
    }
    ptr_accel_free(&accel);
    return (double)stats.rays / stats.seconds / 1e6;
}

int main(int argc, char **argv)
{
    PtrRenderSettings settings = { .width = 400, .height = 225, .samples = 20, .seed = 1,
                                   .max_depth = 50 };
    int runs = 3;
    if (!bench_read_args(argc, argv, "paths", &settings, &runs, INT_MAX))
        return 2;
    PtrScene scene;
    PtrStrings warnings = { 0 };
    PtrError err = { 0 };
    PtrImportOptions options = { 0 };
    if (ptr_import_scene(argv[1], &options, &scene, &warnings, &err) != PTR_OK) {
        fprintf(stderr, "paths: %s\n", err.message);
        return 2;
    }
    ptr_strings_free(&warnings);
    size_t floats = (size_t)settings.width * (size_t)settings.height * 3;
    float *first = malloc(floats * sizeof *first), *rgb = malloc(floats * sizeof *rgb);
    double best[CONFIGS][MAX_THREADS + 1] = { { 0 } };
    int differ = 0, have_first = 0;
    PtrCpuLevel detected = ptr_cpu_level();
    for (int run = 1; run <= runs; run++)
        for (int c = 0; c < CONFIGS; c++) {
            if (configs[c].cap > detected)
                continue;
            for (int threads = 1; threads <= MAX_THREADS; threads++) {
                settings.threads = threads;
                double mrays = render(&scene, &configs[c], settings, have_first ? rgb : first);
                if (have_first && memcmp(first, rgb, floats * sizeof *rgb)) {
                    fprintf(stderr, "paths: %s on %d threads: the image differs\n",
                            configs[c].name, threads);
                    differ = 1;
                }
                have_first = 1;
                printf("run %d  %-28s %d thread%s  %7.2f Mrays/s\n", run, configs[c].name, threads,
                       threads > 1 ? "s" : " ", mrays);
                if (mrays > best[c][threads])
                    best[c][threads] = mrays;
            }
        }
    printf("\nbest of %d runs          1 thread   (x paths)   2 threads   (x paths)   2/1 threads\n",
           runs);
    for (int c = 0; c < CONFIGS; c++)
        if (best[c][1] > 0)
            printf("%-28s %7.2f   %6.2fx      %7.2f    %6.2fx      %5.2fx\n", configs[c].name,
                   best[c][1], best[c][1] / best[0][1], best[c][2], best[c][2] / best[0][2],
                   best[c][2] / best[c][1]);
    ptr_scene_free(&scene);
    free(first);
    free(rgb);
    return differ;
}
