#include "app/report.h"

#include <inttypes.h>
#include <string.h>
#include <unistd.h>

void ptr_job_report_free(PtrJobReport *report)
{
    ptr_strings_free(&report->warnings);
}

void ptr_progress_printer_init(PtrProgressPrinter *printer, const char *label)
{
    *printer = (PtrProgressPrinter){ .label = label, .terminal = isatty(STDERR_FILENO) };
}

static void clock_text(char *buf, size_t size, double seconds)
{
    long s = (long)(seconds + 0.5);
    if (s >= 3600)
        snprintf(buf, size, "%ld:%02ld:%02ld", s / 3600, s / 60 % 60, s % 60);
    else
        snprintf(buf, size, "%ld:%02ld", s / 60, s % 60);
}

void ptr_progress_print(void *user, const PtrProgress *p)
{
    PtrProgressPrinter *printer = user;
    enum { PLAIN_EVERY = 5 }; /* seconds between lines in a log */
    /* In a log: a line as the render starts, then every few seconds. */
    if (!printer->terminal && printer->lines > 0 && p->elapsed - printer->last_line < PLAIN_EVERY)
        return;
    char elapsed[32], left[32] = "?";
    clock_text(elapsed, sizeof elapsed, p->elapsed);
    if (p->fraction > 0.001)
        clock_text(left, sizeof left, p->elapsed / p->fraction * (1.0 - p->fraction));
    double rate = p->rays_seconds > 0 ? (double)p->rays / p->rays_seconds * 1e-6 : 0;
    fprintf(stderr, "%sptr: %s: %3.0f%%, %" PRIu32 "/%" PRIu32 " spp, %s elapsed, %s left, "
                    "%.1f Mrays/s%s",
            printer->terminal ? "\r\033[K" : "", printer->label, 100.0 * p->fraction,
            p->samples_done, p->samples_total, elapsed, left, rate, printer->terminal ? "" : "\n");
    fflush(stderr);
    printer->last_line = p->elapsed;
    printer->lines++;
    printer->drawn = printer->terminal;
}

void ptr_progress_done(PtrProgressPrinter *printer)
{
    if (printer->drawn)
        fputs("\r\033[K", stderr);
    printer->drawn = 0;
}

void ptr_report_stats_line(FILE *out, const PtrJobReport *r)
{
    fprintf(out,
            "ptr: %s: %dx%d, %" PRIu32 " spp%s, %zu spheres, %s, %s intersector: import %.3f s, "
            "build %.3f s, render %.3f s, %.2f Mrays/s (%" PRIu64 " rays)\n",
            r->output, r->width, r->height, r->samples,
            r->interrupted ? " (interrupted)" : r->samples < r->samples_requested ? " (time budget)" : "",
            r->spheres, r->accel, r->kernel, r->import_seconds, r->build_seconds, r->seconds,
            r->seconds > 0 ? (double)r->rays / r->seconds * 1e-6 : 0.0, r->rays);
}

void ptr_json_string(FILE *out, const char *s)
{
    fputc('"', out);
    for (; s && *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\')
            fprintf(out, "\\%c", c);
        else if (c < 0x20)
            fprintf(out, "\\u%04x", c);
        else
            fputc(c, out);
    }
    fputc('"', out);
}

void ptr_report_json(FILE *out, const PtrJobReport *r)
{
    fputs("{\"scene\": ", out);
    ptr_json_string(out, r->scene);
    fputs(", \"output\": ", out);
    ptr_json_string(out, r->output);
    fprintf(out, ", \"status\": \"%s\", \"exit_code\": %d",
            r->result == PTR_OK ? "ok" : "error", ptr_result_exit_code(r->result));
    if (r->result != PTR_OK) {
        fputs(", \"error\": ", out);
        ptr_json_string(out, r->error);
    }
    fprintf(out,
            ", \"width\": %d, \"height\": %d, \"samples\": %" PRIu32 ", \"sample_first\": %" PRIu32
            ", \"samples_requested\": %" PRIu32 ", \"seed\": %" PRIu64 ", \"kernel\": ",
            r->width, r->height, r->samples, r->sample_first, r->samples_requested, r->seed);
    ptr_json_string(out, r->kernel);
    fputs(", \"accel\": ", out);
    ptr_json_string(out, r->accel);
    fputs(", \"integrator\": ", out);
    ptr_json_string(out, r->integrator);
    fprintf(out, ", \"threads\": %d", r->threads);
    fprintf(out,
            ", \"spheres\": %zu, \"import_seconds\": %.6f, \"build_seconds\": %.6f, "
            "\"render_seconds\": %.6f",
            r->spheres, r->import_seconds, r->build_seconds, r->seconds);
    fprintf(out,
            ", \"seconds\": %.6f, \"rays\": %" PRIu64 ", \"rays_per_second\": %.0f, "
            "\"interrupted\": %s, \"warnings\": [",
            r->seconds, r->rays, r->seconds > 0 ? (double)r->rays / r->seconds : 0.0,
            r->interrupted ? "true" : "false");
    for (size_t i = 0; i < r->warnings.count; i++) {
        fputs(i ? ", " : "", out);
        ptr_json_string(out, r->warnings.lines[i]);
    }
    fputs("]}\n", out);
    fflush(out);
}

void ptr_report_summary(FILE *out, const PtrJobReport *reports, int count)
{
    int failed = 0, scene_width = 5, output_width = 6;
    for (int i = 0; i < count; i++) {
        int s = (int)strlen(reports[i].scene), o = reports[i].output ? (int)strlen(reports[i].output) : 1;
        scene_width = s > scene_width ? s : scene_width;
        output_width = o > output_width ? o : output_width;
    }
    fprintf(out, "\n%-*s  %-*s  %-11s %6s %9s %8s\n", scene_width, "scene", output_width, "output",
            "result", "spp", "seconds", "Mrays/s");
    for (int i = 0; i < count; i++) {
        const PtrJobReport *r = &reports[i];
        const char *result = r->result == PTR_OK ? "ok" : r->interrupted ? "interrupted" : "FAILED";
        failed += r->result != PTR_OK;
        fprintf(out, "%-*s  %-*s  %-11s %6" PRIu32 " %9.2f %8.2f\n", scene_width, r->scene,
                output_width, r->output ? r->output : "-", result, r->samples, r->seconds,
                r->seconds > 0 ? (double)r->rays / r->seconds * 1e-6 : 0.0);
    }
    fprintf(out, "%d scene%s, %d failed\n", count, count == 1 ? "" : "s", failed);
}
