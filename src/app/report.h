/* What a render tells its user: a progress line while it runs, a statistics
 * line, one JSON object for scripts, and a summary table after a batch. */
#ifndef PTR_REPORT_H
#define PTR_REPORT_H

#include <stdint.h>
#include <stdio.h>

#include "base/result.h"
#include "importer.h"
#include "render/progressive.h"

/* The outcome of rendering one scene to one image. */
typedef struct PtrJobReport {
    const char *scene, *output;
    PtrResult result;
    char error[512];            /* the one-line message, if result is not PTR_OK */
    int width, height;          /* of the full image */
    uint32_t sample_first, samples, samples_requested;
    uint64_t seed;
    char kernel[16];
    char accel[8];              /* "brute" or "bvh" */
    char integrator[8];         /* "paths" or "bundles" */
    int threads;                /* asked for, or the default (ptr_thread_count) */
    size_t spheres;
    double import_seconds, build_seconds;
    double seconds;             /* rendering */
    uint64_t rays;
    int interrupted;
    PtrStrings warnings;
} PtrJobReport;

void ptr_job_report_free(PtrJobReport *report);

/* Progress on stderr: on a terminal one line redrawn in place; otherwise a
 * plain line every few seconds. */
typedef struct PtrProgressPrinter {
    const char *label;
    int terminal;
    double last_line; /* elapsed time of the last plain line */
    int lines;        /* plain lines printed */
    int drawn;        /* a terminal line is on screen */
} PtrProgressPrinter;

void ptr_progress_printer_init(PtrProgressPrinter *printer, const char *label);
/* Matches PtrProgressiveOptions.report. */
void ptr_progress_print(void *printer, const PtrProgress *progress);
/* Clears a terminal line, so that what follows starts clean. */
void ptr_progress_done(PtrProgressPrinter *printer);

void ptr_report_stats_line(FILE *out, const PtrJobReport *report);
void ptr_report_json(FILE *out, const PtrJobReport *report);
void ptr_report_summary(FILE *out, const PtrJobReport *reports, int count);

/* A JSON string literal. */
void ptr_json_string(FILE *out, const char *text);

#endif /* PTR_REPORT_H */
