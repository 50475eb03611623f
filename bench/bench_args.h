/* The arguments that paths and scaling share: SCENE [WIDTH HEIGHT SPP
 * [RUNS]], the size, samples and runs each with the bench's own default. */
#ifndef PTR_BENCH_ARGS_H
#define PTR_BENCH_ARGS_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "render/settings.h"

/* Reads WIDTH, HEIGHT and SPP into settings and RUNS into *runs, where given:
 * what is not given keeps the caller's default. Returns 0, having printed
 * the usage of the bench called name, for a count of arguments that fits
 * none of the forms. */
static inline int bench_read_args(int argc, char **argv, const char *name,
                                  PtrRenderSettings *settings, int *runs)
{
    if (argc != 2 && argc != 5 && argc != 6) {
        fprintf(stderr, "usage: %s SCENE [WIDTH HEIGHT SPP [RUNS]]\n", name);
        return 0;
    }
    if (argc >= 5) {
        settings->width = atoi(argv[2]);
        settings->height = atoi(argv[3]);
        settings->samples = (uint32_t)atoi(argv[4]);
        *runs = argc == 6 ? atoi(argv[5]) : *runs;
    }
    return 1;
}

#endif /* PTR_BENCH_ARGS_H */
