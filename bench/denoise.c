/* The denoiser's convolutions against the machine's peak, in one run: the
 * peak of fused multiply-adds a core (and on all threads) measured here, then
 * each 3x3 convolution of Open Image Denoise's default U-Net at the size it
 * has in a TILE x TILE tile (full, half, ... 1/16 resolution), on one thread
 * and on all, at every kernel level this CPU runs, with its share of the
 * peak; last, the seconds the convolutions alone take at those rates for a
 * 500x500 and a 1920x1080 image. Times are the threads' CPU clocks (a run
 * takes its slowest thread's), so that other processes' turns on the cores
 * do not count. Then the whole denoiser (ptr_denoise: pre- and
 * post-processing, tiles, every layer) at each quality on synthetic images
 * of those sizes: its wall-clock seconds and the CPU seconds of all its
 * threads, from which the seconds on an otherwise idle machine follow
 * (CPU seconds over threads, when the threads are kept busy).
 *
 *   denoise [TILE]          (default 512)
 *
 * FLOPs count what the kernel computes: 2 a fused multiply-add, channels
 * padded to 16 (the first layer's 9 inputs, the last's 3 outputs). */
#define _DEFAULT_SOURCE /* getloadavg */
#include <math.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "base/cpu.h"
#include "base/threads.h"
#include "denoise/conv.h"
#include "denoise/denoise.h"

void ptr_fma_peak_avx2(uint64_t iterations);
void ptr_fma_peak_avx512(uint64_t iterations);

/* A layer of the network: its name, its resolution as a power-of-two
 * divisor of the image's, its padded input and output channels. */
typedef struct Layer {
    const char *name;
    int scale;
    size_t in, out;
} Layer;

/* OIDN's default network (training/model.py): encoder 32, 48, 64, 80, 96
 * channels, decoder 112, 96, 64, 64, 32, with the skips concatenated. */
static const Layer layers[] = {
    { "enc_conv0", 1, 16, 32 },    { "enc_conv1", 1, 32, 32 },    { "enc_conv2", 2, 32, 48 },
    { "enc_conv3", 4, 48, 64 },    { "enc_conv4", 8, 64, 80 },    { "enc_conv5a", 16, 80, 96 },
    { "enc_conv5b", 16, 96, 96 },  { "dec_conv4a", 8, 160, 112 }, { "dec_conv4b", 8, 112, 112 },
    { "dec_conv3a", 4, 160, 96 },  { "dec_conv3b", 4, 96, 96 },   { "dec_conv2a", 2, 128, 64 },
    { "dec_conv2b", 2, 64, 64 },   { "dec_conv1a", 1, 80, 64 },   { "dec_conv1b", 1, 64, 32 },
    { "dec_conv0", 1, 32, 16 },
};
enum { LAYER_COUNT = sizeof layers / sizeof layers[0] };

/* Work cut into ranges for the threads, timed on each thread's CPU clock:
 * a run takes what its slowest thread took, and other processes on the
 * machine take nothing from the figure. */
typedef struct Timed {
    void (*fn)(void *arg, size_t from, size_t to);
    void *arg;
    _Atomic uint64_t slowest_ns;
} Timed;

static uint64_t thread_cpu_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec;
}

static void timed_range(void *arg, size_t from, size_t to)
{
    Timed *t = arg;
    uint64_t start = thread_cpu_ns();
    t->fn(t->arg, from, to);
    uint64_t ns = thread_cpu_ns() - start, slowest = atomic_load(&t->slowest_ns);
    while (ns > slowest && !atomic_compare_exchange_weak(&t->slowest_ns, &slowest, ns))
        ;
}

/* Runs fn over 0 .. count - 1 on threads threads until a quarter of a
 * second has passed, three times; the best seconds a run. */
static double best_seconds(void (*fn)(void *, size_t, size_t), void *arg, int threads,
                           size_t count)
{
    double best = 1e30;
    for (int rep = 0; rep < 3; rep++) {
        int runs = 0;
        double elapsed = 0;
        do {
            Timed t = { fn, arg, 0 };
            ptr_parallel_ranges(threads, 0, count, timed_range, &t);
            elapsed += 1e-9 * (double)atomic_load(&t.slowest_ns);
            runs++;
        } while (elapsed < 0.25);
        if (elapsed / runs < best)
            best = elapsed / runs;
    }
    return best;
}

/* The peak: the FMA loop once on every thread. */
enum { PEAK_ITERATIONS = 1 << 22 };

static void peak_range(void *arg, size_t from, size_t to)
{
    void (*loop)(uint64_t) = *(void (**)(uint64_t))arg;
    for (size_t t = from; t < to; t++)
        loop(PEAK_ITERATIONS);
}

static double peak_gflops(PtrCpuLevel level, int threads)
{
    void (*loop)(uint64_t) = level >= PTR_CPU_AVX512 ? ptr_fma_peak_avx512 : ptr_fma_peak_avx2;
    double lanes = level >= PTR_CPU_AVX512 ? 16 : 8;
    double flops = 12.0 * lanes * 2.0 * PEAK_ITERATIONS * threads;
    return flops / best_seconds(peak_range, (void *)&loop, threads, (size_t)threads) / 1e9;
}

/* One layer's buffers at one size, and the kernel to time on them. */
typedef struct Conv {
    PtrConv3x3Fn fn;
    const Layer *layer;
    size_t width, height;
    float *src, *dst, *weights, *bias;
} Conv;

static float *floats(size_t count, float value)
{
    float *p = aligned_alloc(64, (count * sizeof(float) + 63) / 64 * 64);
    if (!p) {
        fprintf(stderr, "denoise: out of memory\n");
        exit(2);
    }
    for (size_t i = 0; i < count; i++)
        p[i] = value;
    return p;
}

/* Values that keep every sum finite and away from denormals. */
static void conv_init(Conv *c, const Layer *layer, size_t tile)
{
    c->layer = layer;
    c->width = c->height = tile / (size_t)layer->scale;
    size_t padded = (c->width + 2) * (c->height + 2);
    c->src = floats(padded * layer->in, 0.5f);
    c->dst = floats(padded * layer->out, 0.0f);
    c->weights = floats(ptr_conv_weight_count(layer->in, layer->out), 0.01f);
    c->bias = floats(layer->out, 0.1f);
}

static void conv_free(Conv *c)
{
    free(c->src);
    free(c->dst);
    free(c->weights);
    free(c->bias);
}

static void conv_rows(void *arg, size_t from, size_t to)
{
    const Conv *c = arg;
    size_t row = c->width + 2;
    c->fn(c->dst + ((from + 1) * row + 1) * c->layer->out, c->src + from * row * c->layer->in,
          c->weights, c->bias, c->width, to - from, c->layer->in, c->layer->out, 1);
}

static double layer_flops(const Layer *layer, size_t width, size_t height)
{
    return 2.0 * 9.0 * (double)layer->in * (double)layer->out * (double)width * (double)height;
}

/* The seconds the convolutions take for a width x height image at the
 * rates measured (GFLOP/s by layer). */
static double image_seconds(const double *gflops, size_t width, size_t height)
{
    double seconds = 0;
    for (int i = 0; i < LAYER_COUNT; i++) {
        size_t s = (size_t)layers[i].scale; /* rounded up, as the network pads */
        seconds += layer_flops(&layers[i], (width + s - 1) / s, (height + s - 1) / s) /
                   (gflops[i] * 1e9);
    }
    return seconds;
}

static void bench_level(PtrCpuLevel level, size_t tile, int threads)
{
    PtrConvTable table;
    ptr_conv_init_level(&table, level);
    double peak1 = peak_gflops(level, 1), peak_all = peak_gflops(level, threads);
    printf("\n%s: FMA peak %.1f GFLOP/s on 1 thread, %.1f on %d\n", table.name, peak1, peak_all,
           threads);
    printf("%-11s %9s %9s  %18s  %18s\n", "layer", "size", "channels", "1 thread GFLOP/s",
           "all threads");
    double rate1[LAYER_COUNT], rate_all[LAYER_COUNT], flops_total = 0, seconds1 = 0,
           seconds_all = 0;
    for (int i = 0; i < LAYER_COUNT; i++) {
        Conv c = { .fn = table.conv3x3 };
        conv_init(&c, &layers[i], tile);
        double flops = layer_flops(&layers[i], c.width, c.height);
        double s1 = best_seconds(conv_rows, &c, 1, c.height);
        double s_all = best_seconds(conv_rows, &c, threads, c.height);
        rate1[i] = flops / s1 / 1e9;
        rate_all[i] = flops / s_all / 1e9;
        flops_total += flops;
        seconds1 += s1;
        seconds_all += s_all;
        char size[32], channels[32];
        snprintf(size, sizeof size, "%zux%zu", c.width, c.height);
        snprintf(channels, sizeof channels, "%zu->%zu", layers[i].in, layers[i].out);
        printf("%-11s %9s %9s  %8.1f (%3.0f%% peak)  %8.1f (%3.0f%% peak)\n", layers[i].name,
               size, channels, rate1[i], 100 * rate1[i] / peak1, rate_all[i],
               100 * rate_all[i] / peak_all);
        conv_free(&c);
    }
    double all1 = flops_total / seconds1 / 1e9, all_all = flops_total / seconds_all / 1e9;
    printf("%-11s %9s %9s  %8.1f (%3.0f%% peak)  %8.1f (%3.0f%% peak)\n", "all", "", "", all1,
           100 * all1 / peak1, all_all, 100 * all_all / peak_all);
    printf("the convolutions alone: 500x500 %.3f s, 1920x1080 %.3f s on 1 thread; "
           "%.3f s, %.3f s on %d\n",
           image_seconds(rate1, 500, 500), image_seconds(rate1, 1920, 1080),
           image_seconds(rate_all, 500, 500), image_seconds(rate_all, 1920, 1080), threads);
}

static double clock_seconds(clockid_t clock)
{
    struct timespec ts;
    clock_gettime(clock, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* A rendered image's look, without a renderer: colour with noise and a few
 * fireflies, albedo in blocks, normals that turn across the image. */
static void synthetic_image(float *color, float *albedo, float *normal, size_t width,
                            size_t height)
{
    uint32_t state = 12345;
    for (size_t y = 0; y < height; y++)
        for (size_t x = 0; x < width; x++) {
            size_t i = (y * width + x) * 3;
            for (int c = 0; c < 3; c++) {
                state = state * 1664525u + 1013904223u;
                float noise = (float)(state >> 8) / 16777216.0f;
                albedo[i + c] = 0.2f + 0.6f * (float)(((x / 32 + y / 32 + (size_t)c) % 3)) / 2;
                color[i + c] = albedo[i + c] * 2.0f * noise * noise;
            }
            if (state % 997 == 0)
                color[i] = color[i + 1] = color[i + 2] = 100.0f;
            float nx = (float)x / (float)width - 0.5f, ny = (float)y / (float)height - 0.5f;
            float nz = sqrtf(1.0f - nx * nx - ny * ny);
            normal[i] = nx, normal[i + 1] = ny, normal[i + 2] = nz;
        }
}

/* The whole denoiser at each quality and size: one run each, as a render
 * calls it (weights loaded before). */
static void bench_denoiser(int threads)
{
    static const char *const names[] = { "fast", "balanced", "high" };
    static const size_t sizes[][2] = { { 500, 500 }, { 1920, 1080 } };
    printf("\nthe whole denoiser (ptr_denoise), %d threads: wall seconds (CPU seconds of all "
           "threads)\n%-9s", threads, "quality");
    for (size_t s = 0; s < 2; s++)
        printf(" %26zux%zu", sizes[s][0], sizes[s][1]);
    printf("\n");
    for (int q = PTR_DENOISE_FAST; q <= PTR_DENOISE_HIGH; q++) {
        PtrDenoiser *denoiser;
        PtrError err;
        if (ptr_denoiser_new((PtrDenoiseQuality)q, NULL, ptr_cpu_level(), &denoiser, &err) !=
            PTR_OK) {
            printf("%-9s %s\n", names[q], err.message);
            continue;
        }
        printf("%-9s", names[q]);
        for (size_t s = 0; s < 2; s++) {
            size_t width = sizes[s][0], height = sizes[s][1], n = width * height * 3;
            float *color = floats(n, 0), *albedo = floats(n, 0), *normal = floats(n, 0);
            synthetic_image(color, albedo, normal, width, height);
            PtrDenoiseInput input = { color, albedo, normal, 3, 3, 3, width, height };
            double wall = clock_seconds(CLOCK_MONOTONIC),
                   cpu = clock_seconds(CLOCK_PROCESS_CPUTIME_ID);
            if (ptr_denoise(denoiser, &input, threads, color, 3, &err) != PTR_OK) {
                fprintf(stderr, "denoise: %s\n", err.message);
                exit(2);
            }
            wall = clock_seconds(CLOCK_MONOTONIC) - wall;
            cpu = clock_seconds(CLOCK_PROCESS_CPUTIME_ID) - cpu;
            printf(" %16.3f s (%6.3f s)", wall, cpu);
            fflush(stdout);
            free(color), free(albedo), free(normal);
        }
        printf("\n");
        ptr_denoiser_free(denoiser);
    }
}

int main(int argc, char **argv)
{
    size_t tile = argc > 1 ? strtoul(argv[1], NULL, 10) : 512;
    if (argc > 2 || tile < 16 || tile % 16) {
        fprintf(stderr, "usage: denoise [TILE] (a multiple of 16, default 512)\n");
        return 2;
    }
    int threads = ptr_usable_cpus();
    ptr_threads_keep(threads);
    PtrCpuLevel top = ptr_cpu_level();
    /* Other work on the machine shares the cores' caches and memory with
     * the threads timed (not their CPU clocks). */
    double load = 0;
    getloadavg(&load, 1);
    printf("denoise: CPU level %s, %d threads, %zux%zu tile, load average %.2f\n",
           ptr_cpu_level_name(top), threads, tile, tile, load);
    if (top < PTR_CPU_AVX2) {
        printf("no convolution kernel below avx2\n");
        return 0;
    }
    for (int level = PTR_CPU_AVX2; level <= (int)top; level++)
        bench_level((PtrCpuLevel)level, tile, threads);
    bench_denoiser(threads);
    return 0;
}
