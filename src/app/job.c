#include "app/job.h"

#include <stdlib.h>
#include <string.h>

#include "api/api_internal.h"
#include "app/color_by.h"
#include "app/live_view.h"
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

/* The request the options make of a render. */
static PtrRenderRequest request_of(const PtrOptions *o, const PtrJobReport *report)
{
    return (PtrRenderRequest){
        .width = o->width, .height = o->height, .divisor = o->preview ? PREVIEW_SCALE : 1,
        .region = o->region, .first_sample = report->sample_first,
        .samples = report->samples_requested, .time_budget = o->time_budget, .seed = o->seed,
        .max_depth = o->max_depth, .threads = o->threads, .kernel = o->kernel,
        .level = o->cpu_level, .integrator = o->integrator, .accel = o->accel,
        .sampler = o->sampler, .direct_lighting = o->direct_lighting,
        .noise_threshold = o->noise_threshold, .min_samples = o->min_samples,
        .transparent = o->transparent, .passes = o->passes, .denoiser = o->denoiser,
        .denoise_quality = o->denoise,
    };
}

/* The live view's part in a render (PtrRenderHooks.begin). */
typedef struct LiveRender {
    PtrLiveView *view;
    const char *scene, *output;
    int begun;
} LiveRender;

static void live_begin(void *user, const PtrScene *scene, const PtrAccel *accel,
                       const PtrRenderSettings *settings, PtrProgressiveOptions *passes)
{
    LiveRender *live = user;
    ptr_live_view_begin(live->view, live->scene, live->output, scene, accel, settings, passes);
    live->begun = 1;
}

/* What the render chose and did, into the report. */
static void report_render(const PtrSceneHandle *scene, const PtrFrame *frame,
                          PtrJobReport *report)
{
    if (scene->prepared_valid) {
        const PtrPrepared *prepared = &scene->prepared;
        snprintf(report->kernel, sizeof report->kernel, "%s", prepared->isect.name);
        snprintf(report->integrator, sizeof report->integrator, "%s",
                 ptr_integrator_name(prepared->integrator));
        snprintf(report->accel, sizeof report->accel, "%s", ptr_accel_name(&prepared->accel));
        report->spheres = scene->scene.spheres.count;
        report->build_seconds = prepared->accel.build_seconds;
    }
    if (!frame)
        return;
    report->samples = frame->done.samples_done;
    report->seconds = frame->done.stats.seconds;
    report->rays = frame->done.stats.rays;
    report->interrupted = frame->done.stopped;
}

/* Renders the imported scene (the tree's build reorders its spheres, for
 * either structure) and writes the image. */
static PtrResult render_and_write(const PtrOptions *o, PtrSceneHandle *scene,
                                  const PtrColor *color, PtrJobReport *report, PtrError *err)
{
    const PtrRenderRequest request = request_of(o, report);
    PtrProgressPrinter printer;
    ptr_progress_printer_init(&printer, report->output);
    LiveRender live = { o->live_view, report->scene, report->output, 0 };
    const PtrRenderHooks hooks = {
        .stop = &ptr_stop_requested, .report = o->quiet ? NULL : ptr_progress_print,
        .user = &printer, .begin = live_begin, .begin_user = &live,
    };
    PtrFrame *frame = NULL;
    PtrError problem = { 0 };
    /* The image's size is reported even when its region lies outside it. */
    PtrResult res = ptr_api_render(scene, &request, &hooks, &report->width, &report->height,
                                   &frame, &problem);
    /* The kernel and the integrator were checked before any scene was read:
     * the region is the one option the render can refuse, which the command
     * line names by its option. */
    if (res == PTR_ERR_USAGE)
        ptr_error_set(err, res, "--region: %s", problem.message);
    else if (res != PTR_OK)
        ptr_error_set(err, res, "%s", problem.message);
    ptr_progress_done(&printer);
    report_render(scene, frame, report);
    const int stopped = frame && frame->done.stopped;
    /* A frame of a sequence that --skip-existing resumes is written
     * whole or not at all: an output that exists is never rendered again. */
    if (res == PTR_OK && !(stopped && o->skip_existing)) {
        const PtrOutputSettings output = ptr_options_output(o, color);
        res = ptr_api_frame_finish(frame, report->output, err);
        if (res == PTR_OK)
            res = ptr_api_frame_write(o->images, report->output, frame, &output, err);
    }
    if (live.begun)
        ptr_live_view_end(o->live_view, res == PTR_OK && !stopped);
    if (res == PTR_OK && stopped && o->skip_existing)
        res = ptr_error_set(err, PTR_ERR_INTERRUPTED,
                            "%s: interrupted after %u of %u samples; not written, so that "
                            "--skip-existing renders it again", report->output,
                            report->samples, report->samples_requested);
    else if (res == PTR_OK && stopped)
        res = ptr_error_set(err, PTR_ERR_INTERRUPTED,
                            "%s: interrupted; wrote the %u samples done of %u",
                            report->output, report->samples, report->samples_requested);
    ptr_frame_free(frame);
    return res;
}

PtrResult ptr_job_render(const PtrOptions *o, const char *scene_path, const char *output,
                         const PtrColor *color, PtrStrings *dependencies, PtrJobReport *report)
{
    *report = (PtrJobReport){
        .scene = scene_path, .output = output, .seed = o->seed, .sample_first = o->sample_first,
        .threads = ptr_thread_count(o->threads),
        .samples_requested = o->preview && o->samples > PREVIEW_SAMPLES ? PREVIEW_SAMPLES : o->samples,
    };
    PtrError err = { 0 };
    PtrScene imported;
    PtrImportOptions import = ptr_options_import(o, dependencies);
    double import_start = ptr_now_seconds();
    PtrResult res = ptr_import_scene(scene_path, &import, &imported, &report->warnings, &err);
    report->import_seconds = ptr_now_seconds() - import_start;
    /* A file that failed gets its one line of error, nothing more. */
    for (size_t i = 0; res == PTR_OK && i < report->warnings.count; i++)
        fprintf(stderr, "ptr: warning: %s\n", report->warnings.lines[i]);
    if (res == PTR_OK) {
        if (o->has_sky)
            imported.sky = o->sky;
        res = ptr_color_by_apply(o, scene_path, &imported, color, &err);
        if (res != PTR_OK)
            ptr_scene_free(&imported);
    }
    PtrSceneHandle *scene = NULL;
    if (res == PTR_OK)
        res = ptr_api_scene_adopt(&imported, scene_path, report->import_seconds, &scene, &err);
    if (res == PTR_OK)
        res = render_and_write(o, scene, color, report, &err);
    ptr_scene_handle_free(scene);
    if (res != PTR_OK && res != PTR_ERR_INTERRUPTED)
        return fail(report, &err);
    report->result = res;
    if (res == PTR_ERR_INTERRUPTED)
        snprintf(report->error, sizeof report->error, "%s", err.message);
    if (!o->quiet)
        ptr_report_stats_line(stderr, report);
    return res;
}
