#include "app/job.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "app/color_by.h"
#include "app/live_view.h"
#include "app/output.h"
#include "app/signals.h"
#include "base/cpu.h"
#include "importer.h"
#include "render/progressive.h"

enum { PREVIEW_SCALE = 4, PREVIEW_SAMPLES = 4 };

/* Width and height: the command line's, else the scene's, filling a missing
 * one from the camera's aspect ratio (else the scene's, else 16:9). */
static void choose_size(const PtrOptions *o, const PtrScene *scene, int *width, int *height)
{
    float aspect = scene->camera.aspect > 0.0f ? scene->camera.aspect
                   : scene->width > 0          ? (float)scene->width / (float)scene->height
                                               : 16.0f / 9.0f;
    int w = o->width, h = o->height;
    if (!w && !h && scene->width > 0) {
        w = scene->width;
        h = scene->height;
    }
    if (!w && !h)
        w = PTR_DEFAULT_WIDTH;
    if (!h)
        h = (int)lroundf((float)w / aspect);
    if (!w)
        w = (int)lroundf((float)h * aspect);
    if (o->preview) {
        w /= PREVIEW_SCALE;
        h /= PREVIEW_SCALE;
    }
    *width = w < 1 ? 1 : w > PTR_MAX_IMAGE_SIZE ? PTR_MAX_IMAGE_SIZE : w;
    *height = h < 1 ? 1 : h > PTR_MAX_IMAGE_SIZE ? PTR_MAX_IMAGE_SIZE : h;
}

static PtrResult fail(PtrJobReport *report, const PtrError *err)
{
    report->result = err->code;
    snprintf(report->error, sizeof report->error, "%s", err->message);
    return err->code;
}

/* Renders with the structure chosen and writes the image. */
static PtrResult render_accel(const PtrOptions *o, PtrIntegrator integrator, const PtrScene *scene,
                              const PtrAccel *accel, uint64_t scene_hash, const PtrColor *color,
                              PtrJobReport *report, PtrError *err)
{

    PtrRenderSettings settings = {
        .region = o->region, .seed = o->seed, .max_depth = o->max_depth, .threads = o->threads,
        .sampler = o->sampler, .direct_lighting = o->direct_lighting,
        .noise_threshold = o->noise_threshold, .min_samples = o->min_samples,
        .integrator = integrator, .transparent = o->transparent,
        .passes = o->passes || o->denoise, /* the denoiser's guides */
    };
    choose_size(o, scene, &settings.width, &settings.height);
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
    ptr_live_view_begin(o->live_view, report->scene, report->output, scene, accel, &settings,
                        &passes);
    size_t pixels = (size_t)layout.width * (size_t)layout.height;
    float *rgb = malloc(pixels * 3 * sizeof *rgb);
    float *counts = o->noise_threshold > 0 ? malloc(pixels * sizeof *counts) : NULL;
    float *alpha = o->transparent ? malloc(pixels * sizeof *alpha) : NULL;
    float *albedo = settings.passes ? malloc(pixels * 3 * sizeof *albedo) : NULL;
    float *normal = settings.passes ? malloc(pixels * 3 * sizeof *normal) : NULL;
    if (!rgb || (o->noise_threshold > 0 && !counts) || (o->transparent && !alpha) ||
        (settings.passes && (!albedo || !normal))) {
        free(rgb);
        free(counts);
        free(alpha);
        free(albedo);
        free(normal);
        return ptr_error_set(err, PTR_ERR_NOMEM, "%s: cannot allocate a %dx%d image",
                             report->output, layout.width, layout.height);
    }
    PtrProgressiveResult done;
    PtrResult res = ptr_render_progressive(scene, accel, &settings, &passes, rgb, alpha, counts,
                                           albedo, normal, &done, err);
    ptr_progress_done(&printer);
    if (res == PTR_ERR_SCENE_INVALID) {
        /* The renderer does not know where the scene came from. */
        char message[sizeof err->message];
        memcpy(message, err->message, sizeof message);
        ptr_error_set(err, res, "%s: %s", report->scene, message);
    }
    if (res == PTR_OK) {
        report->samples = done.samples_done;
        report->seconds = done.stats.seconds;
        report->rays = done.stats.rays;
        report->interrupted = done.stopped;
        PtrOutputInfo info = {
            .scene_path = report->scene, .scene_hash = scene_hash,
            .kernel = accel->isect.name, .accel = report->accel, .spheres = report->spheres,
            .import_seconds = report->import_seconds, .build_seconds = report->build_seconds, .sample_first = report->sample_first,
            .samples = done.samples_done, .interrupted = done.stopped, .seed = o->seed,
            .max_depth = o->max_depth, .sampler = ptr_sampler_name(o->sampler),
            .direct_lighting = o->direct_lighting == PTR_ON,
            .noise_threshold = o->noise_threshold, .min_samples = o->min_samples,
            .sample_counts = counts, .albedo = albedo, .normal = normal, .alpha = alpha,
            .denoiser = o->denoiser, .denoise_quality = o->denoise, .threads = o->threads,
            .render_seconds = done.stats.seconds, .depth = o->depth,
            .color = color, .exposure = o->exposure, .bake_view = o->bake_view,
            .dither = o->dither,
        };
        /* A frame of a sequence that --skip-existing resumes is written
         * whole or not at all: an output that exists is never rendered again. */
        if (!(done.stopped && o->skip_existing))
            res = ptr_output_write(o->images, report->output, &layout, rgb, &info, err);
    }
    free(rgb);
    free(counts);
    free(alpha);
    free(albedo);
    free(normal);
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

/* Chooses the structure for the imported scene (the tree's build reorders
 * its spheres, for either), renders and writes the image. */
static PtrResult render_and_write(const PtrOptions *o, PtrScene *scene, const PtrColor *color,
                                  PtrJobReport *report, PtrError *err)
{
    PtrIsectTable isect;
    /* The kernel was checked before any scene was read: this cannot fail. */
    ptr_isect_init(&isect, o->kernel, o->cpu_level, scene->spheres.count, NULL);
    snprintf(report->kernel, sizeof report->kernel, "%s", isect.name);
    PtrIntegrator integrator = ptr_integrator_resolve(o->integrator, o->cpu_level);
    snprintf(report->integrator, sizeof report->integrator, "%s", ptr_integrator_name(integrator));
    /* Before the build, which reorders the spheres and frees the ids that
     * give the file's order, which the hash takes. */
    uint64_t scene_hash;
    PtrError problem;
    PtrResult hashed = ptr_scene_hash(scene, &scene_hash, &problem);
    if (hashed != PTR_OK)
        return ptr_error_set(err, hashed, "%s: %s", report->scene, problem.message);
    PtrAccel accel;
    PtrResult built = ptr_accel_init(&accel, o->accel, &isect,
                                     integrator == PTR_INTEGRATOR_BUNDLES, scene, o->threads,
                                     &problem);
    if (built != PTR_OK)
        return ptr_error_set(err, built, "%s: cannot build the tree over %zu spheres: %s",
                             report->scene, scene->spheres.count, problem.message);
    snprintf(report->accel, sizeof report->accel, "%s", ptr_accel_name(&accel));
    report->spheres = scene->spheres.count;
    report->build_seconds = accel.build_seconds;
    PtrResult res = render_accel(o, integrator, scene, &accel, scene_hash, color, report, err);
    ptr_accel_free(&accel);
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
