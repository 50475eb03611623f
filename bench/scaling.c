/* How ptr's two parallel stages scale from one thread to two, in one run,
 * the thread counts taking turns so that both see the same machine:
 *
 *   scaling SCENE [WIDTH HEIGHT SPP [RUNS]]   (defaults: 640 360 8, 5 runs)
 *
 * Each run imports the scene afresh (the build reorders it), builds the tree
 * as ptr does (ptr_accel_init, the kernels of this CPU) and renders in
 * passes as ptr does (ptr_render_progressive: passes of about a second),
 * on 1 thread and then on 2. Prints per run the build's and the render's
 * seconds and the share of the render threads' time spent idle (waiting for
 * the last tile of a pass, or between passes: PtrRenderStats.idle_seconds);
 * then the medians, and the speed-ups 1 thread / 2 threads. Every render
 * must give the first one's pixels bit for bit: otherwise it says so and
 * exits 1.
 *
 * First it prints what handing work to a kept thread and back costs (a
 * ptr_parallel_ranges of a few microseconds' work on 2 threads, as the
 * build's top levels hand work over): back to back, after the calling
 * thread worked alone for 50 microseconds (the kept thread still watches
 * for work), and after 1 millisecond (it has gone to sleep). */
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "accel/accel.h"
#include "base/cpu.h"
#include "base/threads.h"
#include "bench_args.h"
#include "importer.h"
#include "render/progressive.h"

enum { MAX_THREADS = 2, MAX_RUNS = 99 };

typedef struct Measure {
    double build, render, idle; /* seconds, seconds, share of threads x seconds */
} Measure;

static void fail(const char *what, const PtrError *err)
{
    fprintf(stderr, "scaling: %s: %s\n", what, err->message[0] ? err->message : "out of memory");
    exit(2);
}

static Measure measure(const char *path, PtrRenderSettings settings, float *rgb)
{
    PtrScene scene;
    PtrStrings warnings = { 0 };
    PtrError err = { 0 };
    PtrImportOptions options = { 0 };
    if (ptr_import_scene(path, &options, &scene, &warnings, &err) != PTR_OK)
        fail(path, &err);
    ptr_strings_free(&warnings);
    const PtrCpuLevel level = ptr_cpu_level();
    PtrIsectTable isect;
    PtrAccel accel;
    ptr_isect_init(&isect, PTR_KERNEL_AUTO, level, scene.spheres.count, NULL);
    settings.integrator = ptr_integrator_resolve(PTR_INTEGRATOR_AUTO, level);
    if (ptr_accel_init(&accel, PTR_ACCEL_AUTO, &isect,
                       settings.integrator == PTR_INTEGRATOR_BUNDLES, &scene, settings.threads,
                       &err) != PTR_OK)
        fail("build", &err);
    const PtrProgressiveOptions passes = { .samples = settings.samples };
    const size_t pixels = (size_t)settings.width * (size_t)settings.height;
    float *alpha = malloc(pixels * sizeof *alpha), *counts = malloc(pixels * sizeof *counts);
    PtrProgressiveResult done;
    if (!alpha || !counts ||
        ptr_render_progressive(&scene, &accel, &settings, &passes, rgb, alpha, counts, NULL,
                               NULL, &done, &err) != PTR_OK)
        fail("render", &err);
    const Measure m = { accel.build_seconds, done.stats.seconds,
                        done.stats.idle_seconds / (done.stats.threads * done.stats.seconds) };
    free(alpha);
    free(counts);
    ptr_accel_free(&accel);
    ptr_scene_free(&scene);
    return m;
}

static void add_up(void *arg, size_t from, size_t to)
{
    size_t sum = 0;
    for (size_t i = from; i < to; i++)
        sum += i * i;
    atomic_store_explicit((atomic_size_t *)arg, sum, memory_order_relaxed); /* the sum used */
}

/* Microseconds a handoff and back takes (the time of the parallel call
 * less the half of the work the calling thread does itself), over count
 * handoffs each after alone seconds of the calling thread's own work. */
static double handoff_microseconds(int count, double alone)
{
    enum { WORK = 20000 };
    atomic_size_t sink;
    atomic_init(&sink, 0);
    double start = ptr_now_seconds(), spent_alone = 0.0;
    for (int i = 0; i < count; i++) {
        const double from = ptr_now_seconds();
        while (ptr_now_seconds() - from < alone)
            ;
        spent_alone += ptr_now_seconds() - from;
        ptr_parallel_ranges(2, 0, WORK, add_up, &sink);
    }
    const double handed = ptr_now_seconds() - start - spent_alone;
    start = ptr_now_seconds();
    for (int i = 0; i < count; i++)
        add_up(&sink, 0, WORK / 2);
    return 1e6 * (handed - (ptr_now_seconds() - start)) / count;
}

static int by_value(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *values, int count)
{
    qsort(values, (size_t)count, sizeof *values, by_value);
    return values[count / 2];
}

int main(int argc, char **argv)
{
    PtrRenderSettings settings = { .width = 640, .height = 360, .samples = 8, .seed = 1,
                                   .max_depth = 50 };
    int runs = 5;
    if (!bench_read_args(argc, argv, "scaling", &settings, &runs, MAX_RUNS))
        return 2;
    const size_t floats = (size_t)settings.width * (size_t)settings.height * 3;
    float *first = malloc(floats * sizeof *first), *rgb = malloc(floats * sizeof *rgb);
    if (!first || !rgb)
        return 2;
    double build[MAX_THREADS + 1][MAX_RUNS], render[MAX_THREADS + 1][MAX_RUNS],
        idle[MAX_THREADS + 1][MAX_RUNS];
    int differ = 0;
    ptr_threads_keep(MAX_THREADS);
    printf("handoff to a thread and back: %.1f us back to back, %.1f us after 50 us alone, "
           "%.1f us after 1 ms alone\n\n",
           handoff_microseconds(2000, 0.0), handoff_microseconds(500, 50e-6),
           handoff_microseconds(200, 1e-3));
    printf("run  threads  build s  render s  idle\n");
    for (int run = 0; run < runs; run++)
        for (int threads = 1; threads <= MAX_THREADS; threads++) {
            settings.threads = threads;
            const int is_first = run == 0 && threads == 1;
            const Measure m = measure(argv[1], settings, is_first ? first : rgb);
            if (!is_first && memcmp(first, rgb, floats * sizeof *rgb)) {
                fprintf(stderr, "scaling: run %d on %d threads: the image differs\n", run + 1,
                        threads);
                differ = 1;
            }
            build[threads][run] = m.build;
            render[threads][run] = m.render;
            idle[threads][run] = m.idle;
            printf("%3d  %7d  %7.3f  %8.3f  %5.2f%%\n", run + 1, threads, m.build, m.render,
                   100 * m.idle);
            fflush(stdout);
        }
    double b[MAX_THREADS + 1], r[MAX_THREADS + 1], i[MAX_THREADS + 1];
    for (int threads = 1; threads <= MAX_THREADS; threads++) {
        b[threads] = median(build[threads], runs);
        r[threads] = median(render[threads], runs);
        i[threads] = median(idle[threads], runs);
    }
    printf("\nmedian of %d runs   1 thread   2 threads   1/2 threads\n", runs);
    printf("build s           %8.3f   %9.3f   %10.2fx\n", b[1], b[2], b[1] / b[2]);
    printf("render s          %8.3f   %9.3f   %10.2fx\n", r[1], r[2], r[1] / r[2]);
    printf("render idle       %7.2f%%   %8.2f%%\n", 100 * i[1], 100 * i[2]);
    free(first);
    free(rgb);
    return differ;
}
