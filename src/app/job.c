#include "app/job.h"

#include <stdlib.h>
#include <string.h>

#include "app/color_by.h"
#include "app/live_view.h"
#include "api/output.h"
#include "api/pipeline.h"
#include "app/signals.h"
#include "base/cpu.h"
#include "importer.h"
#include "render/progressive.h"

enum { PREVIEW_SCALE = 4, PREVIEW_SAMPLES = 4 };

static PtrResult fail(PtrJobReport *report, const PtrError *err)
{
    report->result = err->code;
    snprintf(report->error, sizeof report->error, "%s", err->message);
    return err->code;
}

/* Renders the prepared scene and writes the image. */
static PtrResult render_prepared(const PtrOptions *o, const PtrScene *scene,
                                 const PtrPrepared *prepared, const PtrColor *color,
                                 PtrJobReport *report, PtrError *err)
{
    PtrRenderSettings settings = {
        .region = o->region, .seed = o->seed, .max_depth = o->max_depth, .threads = o->threads,
        .sampler = o->sampler, .direct_lighting = o->direct_lighting,
        .noise_threshold = o->noise_threshold, .min_samples = o->min_samples,
        .integrator = prepared->integrator, .transparent = o->transparent,
        .passes = o->passes || o->denoise, /* the denoiser's guides */
    };
    ptr_choose_size(scene, o->width, o->height, o->preview ? PREVIEW_SCALE : 1,
                    &settings.width, &settings.height);
    report->width = settings.width;
    report->height = settings.height;
    PtrRegion region = ptr_render_region(&settings);
    if (region.x1 == 0)
        return ptr_error_set(err, PTR_ERR_USAGE, "--region %d,%d,%d,%d lies outside the %dx%d image",
                             o->region.x0, o->region.y0, o->region.x1, o->region.y1,
                             settings.width, settings.height);
    const PtrImageLayout layout = { region.x1 - region.x0, region.y1 - region.y0, region.x0,
                                    region.y0, settings.width, settings.height };

    PtrProgressPrinter printer;
    ptr_progress_printer_init(&printer, report->output);
    PtrProgressiveOptions passes = {
        .first_sample = report->sample_first, .samples = report->samples_requested,
        .time_budget = o->time_budget, .stop = &ptr_stop_requested,
        .report = o->quiet ? NULL : ptr_progress_print, .user = &printer,
    };
    const PtrAccel *accel = &prepared->accel;
    ptr_live_view_begin(o->live_view, report->scene, report->output, scene, accel, &settings,
                        &passes);
    PtrFrameBuffers frame;
    PtrProgressiveResult done = { 0 };
    PtrResult res = ptr_render_frame(scene, accel, &settings, &passes, report->scene, &frame,
                                     &done, err);
    ptr_progress_done(&printer);
    if (res == PTR_OK) {
        report->samples = done.samples_done;
        report->seconds = done.stats.seconds;
        report->rays = done.stats.rays;
        report->interrupted = done.stopped;
        PtrOutputInfo info = {
            .scene_path = report->scene, .scene_hash = prepared->scene_hash,
            .kernel = accel->isect.name, .accel = report->accel, .spheres = report->spheres,
            .import_seconds = report->import_seconds, .build_seconds = report->build_seconds, .sample_first = report->sample_first,
            .samples = done.samples_done, .interrupted = done.stopped, .seed = o->seed,
            .max_depth = o->max_depth, .sampler = ptr_sampler_name(o->sampler),
            .direct_lighting = o->direct_lighting == PTR_ON,
            .noise_threshold = o->noise_threshold, .min_samples = o->min_samples,
            .sample_counts = frame.sample_counts, .albedo = frame.albedo,
            .normal = frame.normal, .alpha = frame.alpha,
            .denoiser = o->denoiser, .denoise_quality = o->denoise, .threads = o->threads,
            .render_seconds = done.stats.seconds, .depth = o->depth,
            .color = color, .exposure = o->exposure, .bake_view = o->bake_view,
            .dither = o->dither,
        };
        /* A frame of a sequence that --skip-existing resumes is written
         * whole or not at all: an output that exists is never rendered again. */
        if (!(done.stopped && o->skip_existing))
            res = ptr_output_write(o->images, report->output, &layout, frame.rgb, &info, err);
        ptr_frame_buffers_free(&frame);
    }
    ptr_live_view_end(o->live_view, res == PTR_OK && !done.stopped);
    if (res == PTR_OK && done.stopped && o->skip_existing)
        res = ptr_error_set(err, PTR_ERR_INTERRUPTED,
                            "%s: interrupted after %u of %u samples; not written, so that "
                            "--skip-existing renders it again", report->output,
                            done.samples_done, report->samples_requested);
    else if (res == PTR_OK && done.stopped)
        res = ptr_error_set(err, PTR_ERR_INTERRUPTED,
                            "%s: interrupted; wrote the %u samples done of %u",
                            report->output, done.samples_done, report->samples_requested);
    return res;
}

/* Chooses the kernels and the structure for the imported scene (the tree's
 * build reorders its spheres, for either), renders and writes the image. */
static PtrResult render_and_write(const PtrOptions *o, PtrScene *scene, const PtrColor *color,
                                  PtrJobReport *report, PtrError *err)
{
    PtrPrepared prepared;
    /* The kernel was checked before any scene was read: only the tree can
     * fail here. */
    PtrResult res = ptr_prepare_render(scene, o->kernel, o->cpu_level, o->integrator, o->accel,
                                       o->threads, report->scene, &prepared, err);
    if (res != PTR_OK)
        return res;
    snprintf(report->kernel, sizeof report->kernel, "%s", prepared.isect.name);
    snprintf(report->integrator, sizeof report->integrator, "%s",
             ptr_integrator_name(prepared.integrator));
    snprintf(report->accel, sizeof report->accel, "%s", ptr_accel_name(&prepared.accel));
    report->spheres = scene->spheres.count;
    report->build_seconds = prepared.accel.build_seconds;
    res = render_prepared(o, scene, &prepared, color, report, err);
    ptr_prepared_free(&prepared);
    return res;
}

PtrResult ptr_job_render(const PtrOptions *o, const char *scene_path, const char *output,
                         const PtrColor *color, PtrStrings *dependencies, PtrJobReport *report)
{
    *report = (PtrJobReport){
        .scene = scene_path, .output = output, .seed = o->seed, .sample_first = o->sample_first,
        .samples_requested = o->preview && o->samples > PREVIEW_SAMPLES ? PREVIEW_SAMPLES : o->samples,
    };
    PtrError err = { 0 };
    PtrScene scene;
    PtrImportOptions import = ptr_options_import(o, dependencies);
    double import_start = ptr_now_seconds();
    PtrResult res = ptr_import_scene(scene_path, &import, &scene, &report->warnings, &err);
    report->import_seconds = ptr_now_seconds() - import_start;
    /* A file that failed gets its one line of error, nothing more. */
    for (size_t i = 0; res == PTR_OK && i < report->warnings.count; i++)
        fprintf(stderr, "ptr: warning: %s\n", report->warnings.lines[i]);
    if (res == PTR_OK) {
        if (o->has_sky)
            scene.sky = o->sky;
        res = ptr_color_by_apply(o, scene_path, &scene, color, &err);
    }
    if (res == PTR_OK) {
        res = render_and_write(o, &scene, color, report, &err);
    }
    ptr_scene_free(&scene);
    if (res != PTR_OK && res != PTR_ERR_INTERRUPTED)
        return fail(report, &err);
    report->result = res;
    if (res == PTR_ERR_INTERRUPTED)
        snprintf(report->error, sizeof report->error, "%s", err.message);
    if (!o->quiet)
        ptr_report_stats_line(stderr, report);
    return res;
}
