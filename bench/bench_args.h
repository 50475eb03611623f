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
 * what is wrong for the bench called name, for a count of arguments that
 * fits none of the forms, or a size, samples or runs (1 .. max_runs) out of
 * range. */
static inline int bench_read_args(int argc, char **argv, const char *name,
                                  PtrRenderSettings *settings, int *runs, int max_runs)
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
    if (*runs < 1 || *runs > max_runs || settings->width < 1 || settings->height < 1 ||
        settings->samples < 1) {
        fprintf(stderr, "%s: a size, samples and 1 to %d runs\n", name, max_runs);
        return 0;
    }
    return 1;
}

#endif /* PTR_BENCH_ARGS_H */
