/* Runs ptr's denoiser on raw images, for the scripted checks against the
 * NumPy reference (denoise_reference.py):
 *
 *     denoise_raw fast|balanced WIDTH HEIGHT THREADS TILE COLOR ALBEDO NORMAL OUT
 *
 * COLOR, ALBEDO, NORMAL and OUT are little-endian float32 RGB, row by row;
 * TILE is the tiles' side (0: ptr_denoise's own); the CPU level is the
 * machine's capped by $PTR_CPUMASK. Exits 77 (skipped) when the weights are
 * not installed, 1 on any other failure. */
#include <stdio.h>
#include <stdlib.h>

#include "base/cpu.h"
#include "denoise/denoise.h"

static float *read_raw(const char *path, size_t floats)
{
    float *data = malloc(floats * sizeof *data);
    FILE *f = fopen(path, "rb");
    if (!data || !f || fread(data, sizeof *data, floats, f) != floats) {
        fprintf(stderr, "denoise_raw: %s: cannot read %zu floats\n", path, floats);
        exit(1);
    }
    fclose(f);
    return data;
}

int main(int argc, char **argv)
{
    if (argc != 10) {
        fprintf(stderr, "usage: denoise_raw QUALITY WIDTH HEIGHT THREADS TILE COLOR ALBEDO "
                        "NORMAL OUT\n");
        return 1;
    }
    PtrError err;
    PtrDenoiseQuality quality;
    if (ptr_denoise_quality_parse(argv[1], &quality, &err) != PTR_OK) {
        fprintf(stderr, "denoise_raw: %s\n", err.message);
        return 1;
    }
    size_t width = strtoul(argv[2], NULL, 10), height = strtoul(argv[3], NULL, 10);
    int threads = atoi(argv[4]);
    size_t tile = strtoul(argv[5], NULL, 10), floats = width * height * 3;
    PtrDenoiseInput input = { read_raw(argv[6], floats), read_raw(argv[7], floats),
                              read_raw(argv[8], floats), 3, 3, 3, width, height };
    float *out = malloc(floats * sizeof *out);
    PtrDenoiser *denoiser;
    PtrResult res = ptr_denoiser_new(quality, NULL, ptr_cpu_level(), &denoiser, &err);
    if (res == PTR_ERR_INSTALL) {
        fprintf(stderr, "denoise_raw: skipped: %s\n", err.message);
        return 77;
    }
    if (res == PTR_OK) {
        res = tile ? ptr_denoise_tiled(denoiser, &input, tile, threads, out, 3, &err)
                   : ptr_denoise(denoiser, &input, threads, out, 3, &err);
        ptr_denoiser_free(denoiser);
    }
    FILE *f = res == PTR_OK ? fopen(argv[9], "wb") : NULL;
    if (res != PTR_OK || !f || fwrite(out, sizeof *out, floats, f) != floats || fclose(f)) {
        fprintf(stderr, "denoise_raw: %s\n", res != PTR_OK ? err.message : argv[9]);
        return 1;
    }
    free(out);
    free((void *)input.color);
    free((void *)input.albedo);
    free((void *)input.normal);
    return 0;
}
