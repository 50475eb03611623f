#include "render/progressive.h"

#include <math.h>

#include "base/cpu.h"

typedef struct PassWatch {
    const PtrProgressiveOptions *options;
    PtrProgress progress;
    uint32_t pass_samples;
    double start;
} PassWatch;

static void on_tick(void *user, double pass_fraction)
{
    PassWatch *w = user;
    PtrProgress p = w->progress;
    p.fraction = ((double)p.samples_done + pass_fraction * w->pass_samples) / p.samples_total;
    p.elapsed = ptr_now_seconds() - w->start;
    w->options->report(w->options->user, &p);
}

PtrResult ptr_render_progressive(const PtrScene *scene, const PtrAccel *accel,
                                 const PtrRenderSettings *settings,
                                 const PtrProgressiveOptions *options, float *rgb,
                                 float *alpha, float *sample_counts, float *albedo, float *normal,
                                 PtrProgressiveResult *result, PtrError *err)
{
    PtrRegion r = ptr_render_region(settings);
    size_t pixels = (size_t)(r.x1 - r.x0) * (size_t)(r.y1 - r.y0);
    if (options->samples == 0)
        return ptr_error_set(err, PTR_ERR_USAGE, "samples must be positive");
    if (pixels == 0)
        return ptr_error_set(err, PTR_ERR_USAGE, "the region lies outside the %dx%d image",
                             settings->width, settings->height);
    size_t stride = ptr_accum_stride(settings->passes);
    double *acc = ptr_accum_alloc(pixels, stride);
    if (!acc)
        return ptr_error_set(err, PTR_ERR_NOMEM, "cannot allocate a %dx%d image", r.x1 - r.x0,
                             r.y1 - r.y0);

    PassWatch watch = { .options = options, .start = ptr_now_seconds() };
    watch.progress.samples_total = options->samples;
    *result = (PtrProgressiveResult){ 0 };
    PtrResult res = PTR_OK;
    /* About a second a pass keeps progress and a stop responsive at a cost
     * of nothing measurable; with a budget, passes are finer still. */
    double pass_seconds = options->time_budget > 0 ? fmin(1.0, fmax(0.05, options->time_budget / 8))
                                                   : 1.0;
    uint32_t done = 0, pass = 1;
    double passes_seconds = 0.0; /* in ptr_render_samples, the threads at work */
    while (done < options->samples) {
        watch.pass_samples = pass;
        PtrRenderStats stats;
        res = ptr_render_samples(scene, accel, settings, options->first_sample + done, pass, acc,
                                 options->report ? on_tick : NULL, &watch, &stats, err);
        if (res != PTR_OK)
            break;
        done += pass;
        passes_seconds += stats.seconds;
        result->stats.rays += stats.rays;
        result->stats.threads = stats.threads;
        result->stats.idle_seconds += stats.idle_seconds;
        double elapsed = ptr_now_seconds() - watch.start;
        watch.progress.samples_done = done;
        watch.progress.rays = result->stats.rays;
        watch.progress.rays_seconds = elapsed;
        if (options->pass_done) {
            PtrProgress p = watch.progress;
            p.fraction = (double)done / options->samples;
            p.elapsed = elapsed;
            options->pass_done(options->pass_user, acc, pixels, stride, &p);
        }

        if (options->stop && *options->stop) {
            result->stopped = done < options->samples;
            break;
        }
        if (options->time_budget > 0 && elapsed >= options->time_budget)
            break;
        /* Size the next pass from the time a sample has taken so far. */
        double per_sample = elapsed / done;
        double next = per_sample > 0 ? pass_seconds / per_sample : 1e9;
        pass = next < 1 ? 1 : next > options->samples - done ? options->samples - done : (uint32_t)next;
    }
    result->samples_done = done;
    result->stats.seconds = ptr_now_seconds() - watch.start;
    /* Between passes (the pass's set-up, pass_done, sizing the next) every
     * thread waits. */
    result->stats.idle_seconds += (result->stats.seconds - passes_seconds) * result->stats.threads;
    if (res == PTR_OK) {
        ptr_accum_resolve(acc, pixels, stride, rgb, alpha, sample_counts);
        if (settings->passes)
            ptr_accum_resolve_passes(acc, pixels, albedo, normal);
    }
    ptr_accum_free(acc, pixels, stride);
    return res;
}
