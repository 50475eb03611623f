#include "app/cli.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "app/cli_options.h"
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

enum { PATH_SIZE = 4096 };

static int fail(const PtrError *err)
{
    fprintf(stderr, "ptr: %s\n", err->message);
    return ptr_result_exit_code(err->code);
}

/* The output for one scene: -o with {name} replaced by the scene's name; a
 * folder (existing, or written with a trailing /) gets NAME.exr; a plain
 * file name serves one scene only. */
static PtrResult output_for(const PtrOptions *o, const char *scene, char *out, PtrError *err)
{
    const char *base = strrchr(scene, '/') ? strrchr(scene, '/') + 1 : scene;
    const char *dot = strrchr(base, '.');
    int name_len = (int)(dot && dot != base ? (size_t)(dot - base) : strlen(base));
    struct stat st;
    size_t len = strlen(o->output);
    int folder = (len > 0 && o->output[len - 1] == '/') ||
                 (stat(o->output, &st) == 0 && S_ISDIR(st.st_mode));
    int n;
    if (strstr(o->output, "{name}")) {
        const char *at = o->output, *hit;
        out[0] = '\0';
        n = 0;
        while ((hit = strstr(at, "{name}")) && n < PATH_SIZE) {
            n += snprintf(out + n, (size_t)(PATH_SIZE - n), "%.*s%.*s", (int)(hit - at), at,
                          name_len, base);
            at = hit + 6;
        }
        if (n < PATH_SIZE)
            n += snprintf(out + n, (size_t)(PATH_SIZE - n), "%s", at);
    } else if (folder) {
        n = snprintf(out, PATH_SIZE, "%s%s%.*s.exr", o->output,
                     o->output[len - 1] == '/' ? "" : "/", name_len, base);
    } else if (o->input_count > 1) {
        return ptr_error_set(err, PTR_ERR_USAGE,
                             "-o %s: with several scenes, -o must be a folder or a pattern with {name}",
                             o->output);
    } else {
        n = snprintf(out, PATH_SIZE, "%s", o->output);
    }
    if (n >= PATH_SIZE)
        return ptr_error_set(err, PTR_ERR_USAGE, "-o %s: the output path is too long", o->output);
    return PTR_OK;
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

static int render_all(const PtrOptions *o, const PtrColor *color)
{
    PtrError err = { 0 };
    char (*outputs)[PATH_SIZE] = calloc((size_t)o->input_count, PATH_SIZE);
    PtrJobReport *reports = calloc((size_t)o->input_count, sizeof *reports);
    int code = 0, done = 0;
    if (!outputs || !reports) {
        ptr_error_set(&err, PTR_ERR_NOMEM, "out of memory");
        code = fail(&err);
        goto end;
    }
    /* Every output is settled before anything renders. */
    for (int i = 0; i < o->input_count; i++) {
        if (output_for(o, o->inputs[i], outputs[i], &err) == PTR_OK)
            ptr_output_check(outputs[i], o->depth, &err);
        for (int j = 0; err.code == PTR_OK && j < i; j++)
            if (!strcmp(outputs[i], outputs[j]))
                ptr_error_set(&err, PTR_ERR_USAGE, "%s and %s would both be written to %s",
                              o->inputs[j], o->inputs[i], outputs[i]);
        if (err.code != PTR_OK) {
            code = fail(&err);
            goto end;
        }
    }
    int failed = 0;
    for (; done < o->input_count && !ptr_stop_requested; done++) {
        ptr_job_render(o, o->inputs[done], outputs[done], color, NULL, &reports[done]);
        code = finish_job(o, &reports[done]);
        failed += reports[done].result != PTR_OK;
    }
    if (o->input_count > 1) {
        if (!o->quiet)
            ptr_report_summary(stderr, reports, done);
        code = ptr_stop_requested ? ptr_result_exit_code(PTR_ERR_INTERRUPTED)
               : failed           ? ptr_result_exit_code(PTR_ERR_BATCH)
                                  : 0;
    }
end:
    for (int i = 0; reports && i < done; i++)
        ptr_job_report_free(&reports[i]);
    free(reports);
    free(outputs);
    return code;
}

/* Renders, then again whenever the scene's files change, until a signal. A
 * broken save is reported and the last good image kept. */
static int watch_scene(const PtrOptions *o, const PtrColor *color)
{
    char output[PATH_SIZE];
    PtrError err = { 0 };
    if (output_for(o, o->inputs[0], output, &err) != PTR_OK ||
        ptr_output_check(output, o->depth, &err) != PTR_OK)
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

int ptr_cli_main(int argc, char **argv)
{
    PtrOptions o;
    int code = ptr_options_parse(argc, argv, &o);
    if (code >= 0)
        return code;
    ptr_signals_install();

    if (o.dump_scene)
        return dump_scenes(&o);

    PtrError err = { 0 };
    /* Renders and merges write images. For any format but EXR, OpenImageIO
     * loads on a thread of its own while the colour config, the scenes and
     * the render proceed. The tree's and the render's threads start first:
     * no thread can start while the load runs. */
    char first_output[PATH_SIZE];
    if (!o.list_views) {
        int threads = o.threads > 0 ? o.threads : ptr_online_cpus();
        ptr_threads_keep(threads);
        if (ptr_image_set_threads(threads, &err) != PTR_OK)
            return fail(&err);
        const char *output = o.merge ? o.output
                             : output_for(&o, o.inputs[0], first_output, &err) == PTR_OK
                                 ? first_output
                                 : NULL;
        if (output && ptr_image_preload(output, &err) != PTR_OK)
            return fail(&err);
    }
    PtrColor *color = ptr_color_open(o.ocio_config, &err);
    if (!color)
        return fail(&err);
    if (ptr_color_select(color, o.display, o.view, o.look, o.exposure, &err) != PTR_OK) {
        code = fail(&err);
    } else if (o.list_views) {
        code = ptr_color_list(color, stdout, &err) == PTR_OK ? 0 : fail(&err);
    } else if (o.merge) {
        PtrJobReport report;
        ptr_merge(o.inputs, o.input_count, o.output, &o, color, &report);
        code = finish_job(&o, &report);
        ptr_job_report_free(&report);
    } else {
        /* Refuse an unavailable kernel or integrator before reading any scene. */
        PtrIsectTable isect;
        if (!ptr_isect_init(&isect, o.kernel, SIZE_MAX)) {
            ptr_error_set(&err, PTR_ERR_USAGE,
                          "--asm: no assembly intersector at CPU level '%s' (this build %s)",
                          ptr_cpu_level_name(ptr_cpu_level()),
                          ptr_isect_has_asm() ? "has them" : "was built without them");
            code = fail(&err);
        } else if (!ptr_integrator_available(o.integrator)) {
            int built = ptr_integrator_for_level(PTR_CPU_LEVEL_COUNT - 1) == PTR_INTEGRATOR_BUNDLES;
            ptr_error_set(&err, PTR_ERR_USAGE,
                          "--integrator %s: not at CPU level '%s' (this build %s)",
                          ptr_integrator_name(o.integrator), ptr_cpu_level_name(ptr_cpu_level()),
                          built ? "has them from AVX2 on" : "was built without them");
            code = fail(&err);
        } else if (ptr_live_view_open(&o, color, &err) != PTR_OK) {
            code = fail(&err);
        } else {
            code = o.watch ? watch_scene(&o, color) : render_all(&o, color);
        }
        ptr_live_view_close();
    }
    ptr_color_close(color);
    return code;
}
