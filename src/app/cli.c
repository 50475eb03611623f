#include "app/cli.h"

#include <stdio.h>
#include <stdlib.h>

#include "app/batch.h"
#include "app/claim.h"
#include "app/cli_help.h"
#include "app/cli_options.h"
#include "app/color_by.h"
#include "app/job.h"
#include "app/live_view.h"
#include "app/merge.h"
#include "app/report.h"
#include "app/scene_json.h"
#include "app/signals.h"
#include "app/watch.h"
#include "base/cpu.h"
#include "base/threads.h"
#include "color/color.h"
#include "image/image.h"
#include "importer.h"

static int fail(const PtrError *err)
{
    fprintf(stderr, "ptr: %s\n", err->message);
    return ptr_result_exit_code(err->code);
}

static int dump_scenes(const PtrOptions *o)
{
    int code = 0;
    for (int i = 0; i < o->input_count; i++) {
        PtrScene scene;
        PtrStrings warnings = { 0 };
        PtrError err = { 0 };
        PtrImportOptions import = ptr_options_import(o, NULL);
        PtrResult res = ptr_import_scene(o->inputs[i], &import, &scene, &warnings, &err);
        for (size_t w = 0; res == PTR_OK && w < warnings.count; w++)
            fprintf(stderr, "ptr: warning: %s\n", warnings.lines[w]);
        if (res == PTR_OK) {
            if (o->has_sky)
                scene.sky = o->sky;
            res = ptr_color_by_apply(o, o->inputs[i], &scene, NULL, &err);
        }
        if (res == PTR_OK) {
            res = ptr_scene_write_json(stdout, o->inputs[i], &scene, &warnings);
            if (res != PTR_OK)
                ptr_error_set(&err, res, "%s: %s", o->inputs[i], ptr_result_description(res));
        }
        if (res != PTR_OK) {
            int failed = fail(&err);
            code = code ? code : failed;
        }
        ptr_strings_free(&warnings);
        ptr_scene_free(&scene);
    }
    return code;
}

/* Prints what a finished job needs said, and returns its exit code. */
static int finish_job(const PtrOptions *o, PtrJobReport *report)
{
    if (report->result != PTR_OK)
        fprintf(stderr, "ptr: %s\n", report->error);
    if (o->json)
        ptr_report_json(stdout, report);
    return ptr_result_exit_code(report->result);
}

/* With --skip-existing: whether to render item, having claimed it. */
static int claim_item(const PtrOptions *o, const PtrBatchItem *item, int *code)
{
    char holder[300];
    PtrError err = { 0 };
    switch (ptr_claim_take(item->output, holder, sizeof holder, &err)) {
    case PTR_CLAIM_TAKEN: return 1;
    case PTR_CLAIM_EXISTS:
        if (!o->quiet)
            fprintf(stderr, "ptr: %s exists: skipped\n", item->output);
        return 0;
    case PTR_CLAIM_BUSY:
        if (!o->quiet)
            fprintf(stderr, "ptr: %s is being rendered by %s: skipped\n", item->output,
                    holder[0] ? holder : "another process");
        return 0;
    case PTR_CLAIM_FAILED: break;
    }
    *code = fail(&err);
    return 0;
}

static int render_all(const PtrOptions *o, const PtrColor *color)
{
    PtrError err = { 0 };
    PtrBatchItem *items;
    int count;
    PtrStructureFile *structure;
    if (ptr_batch_plan(o, &items, &count, &structure, &err) != PTR_OK)
        return fail(&err);
    PtrJobReport *reports = calloc((size_t)count, sizeof *reports);
    if (!reports) {
        ptr_batch_free(items, count);
        ptr_structure_close(structure);
        ptr_error_set(&err, PTR_ERR_NOMEM, "out of memory");
        return fail(&err);
    }
    int code = 0, done = 0, failed = 0;
    for (int i = 0; i < count && !ptr_stop_requested; i++) {
        int claim_code = 0;
        if (o->skip_existing && !claim_item(o, &items[i], &claim_code)) {
            failed += claim_code != 0;
            code = claim_code ? claim_code : code;
            continue;
        }
        PtrOptions frame = *o;
        frame.orbit_degrees = items[i].orbit_degrees;
        frame.structure_model = items[i].model;
        frame.structure_file = structure;
        ptr_job_render(&frame, items[i].scene, items[i].output, color, NULL, &reports[done]);
        if (o->skip_existing)
            ptr_claim_release(items[i].output);
        code = finish_job(o, &reports[done]);
        failed += reports[done++].result != PTR_OK;
    }
    if (count > 1) {
        if (!o->quiet && done > 0)
            ptr_report_summary(stderr, reports, done);
        code = ptr_stop_requested ? ptr_result_exit_code(PTR_ERR_INTERRUPTED)
               : failed           ? ptr_result_exit_code(PTR_ERR_BATCH)
                                  : 0;
    }
    for (int i = 0; i < done; i++)
        ptr_job_report_free(&reports[i]);
    free(reports);
    ptr_batch_free(items, count);
    ptr_structure_close(structure);
    return code;
}

/* Renders, then again whenever the scene's files change, until a signal. A
 * broken save is reported and the last good image kept. */
static int watch_scene(const PtrOptions *o, const PtrColor *color)
{
    char output[PTR_PATH_SIZE];
    PtrError err = { 0 };
    if (ptr_batch_output(o, o->inputs[0], output, &err) != PTR_OK ||
        ptr_output_check(o->images, output, o->depth, o->transparent, o->passes, &err) != PTR_OK)
        return fail(&err);
    PtrWatch watch = { 0 };
    int code = 0;
    for (;;) {
        PtrStrings dependencies = { 0 };
        PtrJobReport report;
        ptr_job_render(o, o->inputs[0], output, color, &dependencies, &report);
        code = finish_job(o, &report);
        if (report.result != PTR_OK && report.result != PTR_ERR_INTERRUPTED)
            fprintf(stderr, "ptr: %s: keeping the last good image; watching for the next save\n",
                    output);
        /* A scene that failed to import names no files: keep watching the old ones. */
        if (report.result == PTR_OK || !watch.count)
            ptr_watch_set(&watch, o->inputs[0], &dependencies);
        ptr_strings_free(&dependencies);
        ptr_job_report_free(&report);
        if (ptr_stop_requested || !ptr_watch_wait(&watch, &ptr_stop_requested))
            break;
        if (!o->quiet)
            fprintf(stderr, "ptr: %s changed: rendering again\n", o->inputs[0]);
    }
    ptr_watch_free(&watch);
    /* Stopped while waiting: a normal end. Stopped mid-render: exit 8. */
    return code == ptr_result_exit_code(PTR_ERR_INTERRUPTED) ? code : 0;
}

/* What the command line asks for once parsed: renders, a merge or the list of
 * views. */
static int run(const PtrOptions *o)
{
    PtrError err = { 0 };
    int code = 0;
    /* Renders and merges write images. For any format but EXR, OpenImageIO
     * loads on a thread of its own while the colour config, the scenes and
     * the render proceed. The tree's and the render's threads start first:
     * no thread can start while the load runs. */
    char first_output[PTR_PATH_SIZE];
    if (!o->list_views) {
        int threads = ptr_thread_count(o->threads);
        ptr_threads_keep(threads);
        if (o->skip_existing && ptr_claim_keeper_start(&err) != PTR_OK)
            return fail(&err);
        if (ptr_image_set_threads(threads, &err) != PTR_OK)
            return fail(&err);
        const char *output = o->merge ? o->output
                             : ptr_batch_output(o, o->inputs[0], first_output, &err) == PTR_OK
                                 ? first_output
                                 : NULL;
        if (output && ptr_image_preload(o->images, output, &err) != PTR_OK)
            return fail(&err);
    }
    PtrColor *color;
    if (ptr_color_open(o->ocio_config, &color, &err) != PTR_OK)
        return fail(&err);
    if (ptr_color_select(color, o->display, o->view, o->look, o->exposure, &err) != PTR_OK) {
        code = fail(&err);
    } else if (o->list_views) {
        code = ptr_color_list(color, stdout, &err) == PTR_OK ? 0 : fail(&err);
    } else if (o->merge) {
        PtrJobReport report;
        ptr_merge(o->inputs, o->input_count, o->output, o, color, &report);
        code = finish_job(o, &report);
        ptr_job_report_free(&report);
    } else {
        /* Refuse an unavailable kernel or integrator before reading any scene. */
        PtrIsectTable isect;
        PtrError kernel_err;
        if (ptr_isect_init(&isect, o->kernel, o->cpu_level, SIZE_MAX, &kernel_err) != PTR_OK) {
            ptr_error_set(&err, kernel_err.code, "--asm: %s", kernel_err.message);
            code = fail(&err);
        } else if (!ptr_integrator_available(o->integrator, o->cpu_level)) {
            int built = ptr_integrator_for_level(PTR_CPU_LEVEL_COUNT - 1) == PTR_INTEGRATOR_BUNDLES;
            ptr_error_set(&err, PTR_ERR_USAGE,
                          "--integrator %s: not at CPU level '%s' (this build %s)",
                          ptr_integrator_name(o->integrator), ptr_cpu_level_name(o->cpu_level),
                          built ? "has them from AVX2 on" : "was built without them");
            code = fail(&err);
        } else {
            PtrOptions rendering = *o;
            if (ptr_live_view_open(o, color, &rendering.live_view, &err) != PTR_OK)
                code = fail(&err);
            else
                code = o->watch ? watch_scene(&rendering, color) : render_all(&rendering, color);
            ptr_live_view_close(rendering.live_view);
        }
    }
    ptr_color_close(color);
    ptr_claim_keeper_stop();
    return code;
}

int ptr_cli_main(int argc, char **argv)
{
    PtrOptions o;
    PtrError err = { 0 };
    if (ptr_options_parse(argc, argv, &o, &err) != PTR_OK)
        return fail(&err);
    if (o.print != PTR_PRINT_NOTHING) {
        ptr_print_requested(&o);
        return 0;
    }
    ptr_signals_install();
    /* The weights load once for every image of the run, and a missing file
     * is said before anything renders. */
    if (o.denoise && !o.dump_scene && !o.list_views &&
        ptr_denoiser_new(o.denoise_quality, NULL, o.cpu_level, &o.denoiser, &err) != PTR_OK)
        return fail(&err);
    int code;
    if (ptr_image_loader_new(&o.images, &err) != PTR_OK) {
        code = fail(&err);
    } else {
        code = o.dump_scene ? dump_scenes(&o) : run(&o);
        ptr_image_loader_free(o.images);
    }
    ptr_denoiser_free(o.denoiser);
    return code;
}
