/* The public API's renders and frames (include/ptr/ptr.h), through the
 * command line's steps (api/pipeline.h, api/output.h). */
#include <signal.h>
#include <stdlib.h>
#include <string.h>

#include "api/api_internal.h"
#include "api/output.h"
#include "builder.h"

struct PtrFrame {
    int width, height, channels;
    /* rgb: the colour shown, denoised if asked for. */
    PtrFrameBuffers buffers;
    float *rgba;        /* the colour with alpha, with a transparent background; else NULL */
    char *scene_name;   /* info.scene_path */
    PtrOutputInfo info; /* the metadata of a saved image, without the pixels */
};

/* What a render's options choose, read and checked. */
typedef struct Choices {
    PtrKernel kernel;
    PtrCpuLevel level;
    PtrIntegrator integrator;
    PtrAccelChoice accel;
    PtrSamplerKind sampler;
    int has_sky;
    PtrSky sky;
    int denoise;
    PtrDenoiseQuality denoise_quality;
} Choices;

void ptr_render_options_default(PtrRenderOptions *options)
{
    *options = (PtrRenderOptions){
        .samples = PTR_DEFAULT_SAMPLES, .seed = PTR_DEFAULT_SEED,
        .max_depth = PTR_DEFAULT_MAX_DEPTH, .min_samples = PTR_DEFAULT_MIN_SAMPLES,
        .direct_lighting = 1,
    };
}

/* A parser's error, with the option's name before it. */
static PtrResult option_error(const char *name, const PtrError *problem, PtrError *err)
{
    return ptr_error_set(err, PTR_ERR_USAGE, "%s: %s", name, problem->message);
}

static PtrResult read_choices(const PtrContext *context, const PtrRenderOptions *o, Choices *c,
                              PtrError *err)
{
    PtrError problem;
    *c = (Choices){ .level = context->cpu_level };
    if (o->kernel && strcmp(o->kernel, "c") && strcmp(o->kernel, "asm"))
        return ptr_error_set(err, PTR_ERR_USAGE, "kernel: '%s' is not c or asm", o->kernel);
    c->kernel = !o->kernel ? PTR_KERNEL_AUTO : o->kernel[0] == 'c' ? PTR_KERNEL_C : PTR_KERNEL_ASM;
    PtrCpuLevel cap;
    if (o->cpu_cap && ptr_cpu_parse_level(o->cpu_cap, &cap, &problem) != PTR_OK)
        return option_error("cpu_cap", &problem, err);
    if (o->cpu_cap && cap < c->level)
        c->level = cap;
    if (o->integrator && ptr_integrator_parse(o->integrator, &c->integrator, &problem) != PTR_OK)
        return option_error("integrator", &problem, err);
    if (!ptr_integrator_available(c->integrator, c->level))
        return ptr_error_set(err, PTR_ERR_USAGE, "integrator: %s is not available at CPU level %s",
                             ptr_integrator_name(c->integrator), ptr_cpu_level_name(c->level));
    if (o->accel && ptr_accel_parse(o->accel, &c->accel, &problem) != PTR_OK)
        return option_error("accel", &problem, err);
    if (o->sampler && ptr_sampler_parse(o->sampler, &c->sampler, &problem) != PTR_OK)
        return option_error("sampler", &problem, err);
    c->has_sky = o->sky != NULL;
    if (o->sky && ptr_sky_parse(o->sky, &c->sky, &problem) != PTR_OK)
        return option_error("sky", &problem, err);
    c->denoise = o->denoise != NULL;
    if (o->denoise && ptr_denoise_quality_parse(o->denoise, &c->denoise_quality, &problem) != PTR_OK)
        return option_error("denoise", &problem, err);
    /* The command line's ranges; 0 is the scene's size and the context's
     * threads. */
    const struct {
        const char *name;
        PtrRenderNumber number;
        long long value;
    } numbers[] = {
        { "width", PTR_NUMBER_SIZE, o->width ? o->width : 1 },
        { "height", PTR_NUMBER_SIZE, o->height ? o->height : 1 },
        { "samples", PTR_NUMBER_SAMPLES, o->samples },
        { "min_samples", PTR_NUMBER_MIN_SAMPLES, o->min_samples },
        { "max_depth", PTR_NUMBER_MAX_DEPTH, o->max_depth },
        { "threads", PTR_NUMBER_THREADS, o->threads },
    };
    for (size_t n = 0; n < sizeof numbers / sizeof numbers[0]; n++)
        if (ptr_api_check_number(numbers[n].name, numbers[n].number, numbers[n].value, err) !=
            PTR_OK)
            return PTR_ERR_USAGE;
    if (o->noise_threshold != 0 && !ptr_noise_threshold_ok(o->noise_threshold))
        return ptr_error_set(err, PTR_ERR_USAGE,
                             "noise_threshold: %g is not 0 (off) or above 0 and at most 10^6",
                             (double)o->noise_threshold);
    const char *wrong = ptr_sample_range_problem(o->noise_threshold, o->first_sample, o->samples);
    if (wrong)
        return ptr_error_set(err, PTR_ERR_USAGE, "samples: %s", wrong);
    return PTR_OK;
}

/* The camera desc as the scene's, relative to its origin, into camera;
 * PTR_ERR_USAGE if it is not finite. */
static PtrResult camera_at(const PtrCameraDesc *desc, const double origin[3], PtrCamera *camera,
                           PtrError *err)
{
    PtrCameraSpec spec;
    PtrResult res = ptr_api_camera_spec(desc, &spec, err);
    if (res != PTR_OK)
        return res;
    *camera = ptr_camera_lens(&spec);
    camera->lookfrom = v3((float)(desc->lookfrom[0] - origin[0]),
                          (float)(desc->lookfrom[1] - origin[1]),
                          (float)(desc->lookfrom[2] - origin[2]));
    camera->lookat = v3((float)(desc->lookat[0] - origin[0]), (float)(desc->lookat[1] - origin[1]),
                        (float)(desc->lookat[2] - origin[2]));
    camera->up = v3((float)desc->up[0], (float)desc->up[1], (float)desc->up[2]);
    return PTR_OK;
}

/* The scene's kernels and tree for these choices, built unless already. */
static PtrResult prepare(PtrSceneHandle *h, const Choices *c, int threads, PtrError *err)
{
    const PtrPreparedFor wanted = { c->kernel, c->level, c->integrator, c->accel };
    if (h->prepared_valid && !memcmp(&wanted, &h->prepared_for, sizeof wanted))
        return PTR_OK;
    if (h->prepared_valid)
        ptr_prepared_free(&h->prepared);
    h->prepared_valid = 0;
    PtrResult res = ptr_prepare_render(&h->scene, c->kernel, c->level, c->integrator, c->accel,
                                       threads, h->name, &h->prepared, err);
    if (res != PTR_OK)
        return res;
    if (h->hash_valid)
        h->prepared.scene_hash = h->scene_hash;
    h->scene_hash = h->prepared.scene_hash;
    h->hash_valid = 1;
    h->prepared_valid = 1;
    h->prepared_for = wanted;
    return PTR_OK;
}

/* The denoiser of this quality, loaded on first use. */
static PtrResult denoiser(PtrContext *context, PtrDenoiseQuality quality, PtrError *err)
{
    if (context->denoisers[quality])
        return PTR_OK;
    return ptr_denoiser_new(quality, context->weights_dir, context->cpu_level,
                            &context->denoisers[quality], err);
}

typedef struct Progress {
    PtrProgressCallback callback;
    void *user;
    volatile sig_atomic_t stop;
} Progress;

static void report_progress(void *user, const PtrProgress *p)
{
    Progress *progress = user;
    const PtrProgressInfo info = { p->samples_done, p->samples_total, p->fraction, p->elapsed };
    if (progress->callback(progress->user, &info))
        progress->stop = 1;
}

/* Makes the frame's colour the denoised one, and with alpha its RGBA. */
static PtrResult finish_frame(PtrFrame *f, PtrError *err)
{
    const PtrImageLayout layout = { f->width, f->height, 0, 0, f->width, f->height };
    size_t pixels = (size_t)f->width * (size_t)f->height;
    if (f->info.denoiser) {
        float *denoised;
        PtrResult res = ptr_output_denoise(f->scene_name, &layout, f->buffers.rgb, &f->info,
                                           &denoised, err);
        if (res != PTR_OK)
            return res;
        free(f->buffers.rgb);
        f->buffers.rgb = denoised;
        /* Saved as it is: it is denoised already. */
        f->info.denoiser = NULL;
    }
    if (f->buffers.alpha) {
        f->rgba = malloc(pixels * 4 * sizeof *f->rgba);
        if (!f->rgba)
            return ptr_error_set(err, PTR_ERR_NOMEM, "%s: out of memory", f->scene_name);
        for (size_t p = 0; p < pixels; p++) {
            memcpy(&f->rgba[4 * p], &f->buffers.rgb[3 * p], 3 * sizeof *f->rgba);
            f->rgba[4 * p + 3] = f->buffers.alpha[p];
        }
    }
    return PTR_OK;
}

/* Renders into a new frame, the choices read. */
static PtrResult render(PtrContext *context, PtrSceneHandle *h, const PtrRenderOptions *o,
                        const Choices *c, Progress *progress, PtrFrame **out, PtrError *err)
{
    const int threads = o->threads ? o->threads : context->threads;
    if (c->denoise) {
        PtrResult res = denoiser(context, c->denoise_quality, err);
        if (res != PTR_OK)
            return res;
    }
    PtrCamera camera = h->scene.camera;
    PtrResult res = o->camera ? camera_at(o->camera, h->scene.origin, &camera, err) : PTR_OK;
    if (res == PTR_OK)
        res = prepare(h, c, threads, err);
    if (res != PTR_OK)
        return res;
    PtrRenderSettings settings = {
        .seed = o->seed, .max_depth = o->max_depth, .threads = threads, .sampler = c->sampler,
        .direct_lighting = o->direct_lighting ? PTR_ON : PTR_OFF,
        .noise_threshold = o->noise_threshold, .min_samples = o->min_samples,
        .integrator = h->prepared.integrator, .transparent = o->transparent,
        .passes = o->passes || c->denoise, /* the denoiser's guides */
    };
    /* This render's sky and camera, the scene's own kept for the next. */
    const PtrSky sky = h->scene.sky;
    const PtrCamera scene_camera = h->scene.camera;
    if (c->has_sky)
        h->scene.sky = c->sky;
    h->scene.camera = camera;
    ptr_choose_size(&h->scene, o->width, o->height, 1, &settings.width, &settings.height);
    const PtrProgressiveOptions passes = {
        .first_sample = o->first_sample, .samples = o->samples, .stop = &progress->stop,
        .report = progress->callback ? report_progress : NULL, .user = progress,
    };
    PtrFrame *f = calloc(1, sizeof *f);
    PtrProgressiveResult done = { 0 };
    if (!f || !(f->scene_name = strdup(h->name)))
        res = ptr_error_set(err, PTR_ERR_NOMEM, "%s: out of memory", h->name);
    else
        res = ptr_render_frame(&h->scene, &h->prepared.accel, &settings, &passes, h->name,
                               &f->buffers, &done, err);
    h->scene.sky = sky;
    h->scene.camera = scene_camera;
    if (!f)
        return res;
    f->width = settings.width;
    f->height = settings.height;
    f->channels = o->transparent ? 4 : 3;
    f->info = (PtrOutputInfo){
        .scene_path = f->scene_name, .scene_hash = h->prepared.scene_hash,
        .kernel = h->prepared.accel.isect.name, .accel = ptr_accel_name(&h->prepared.accel),
        .spheres = h->scene.spheres.count, .import_seconds = h->import_seconds,
        .build_seconds = h->prepared.accel.build_seconds, .sample_first = o->first_sample,
        .samples = done.samples_done, .seed = o->seed, .max_depth = o->max_depth,
        .sampler = ptr_sampler_name(c->sampler), .direct_lighting = o->direct_lighting != 0,
        .noise_threshold = o->noise_threshold, .min_samples = o->min_samples,
        .sample_counts = f->buffers.sample_counts, .albedo = f->buffers.albedo,
        .normal = f->buffers.normal, .alpha = f->buffers.alpha,
        .denoiser = c->denoise ? context->denoisers[c->denoise_quality] : NULL,
        .threads = threads,
        .render_seconds = done.stats.seconds,
    };
    if (res == PTR_OK && done.stopped)
        res = ptr_error_set(err, PTR_ERR_INTERRUPTED, "%s: cancelled after %u of %u samples",
                            h->name, done.samples_done, o->samples);
    if (res == PTR_OK)
        res = finish_frame(f, err);
    if (res != PTR_OK) {
        ptr_frame_free(f);
        return res;
    }
    *out = f;
    return PTR_OK;
}

PtrStatus ptr_scene_render(PtrContext *context, PtrSceneHandle *scene,
                           const PtrRenderOptions *options, PtrProgressCallback callback,
                           void *user, PtrFrame **out, PtrErrorInfo *err)
{
    PtrError e;
    Choices choices;
    Progress progress = { callback, user, 0 };
    if (!context || !scene || !options || !out)
        return ptr_api_usage(err, "render: context, scene, options and out are needed, not NULL");
    if (read_choices(context, options, &choices, &e) != PTR_OK ||
        render(context, scene, options, &choices, &progress, out, &e) != PTR_OK)
        return ptr_api_fail(err, &e);
    return PTR_STATUS_OK;
}

int ptr_frame_width(const PtrFrame *frame) { return frame ? frame->width : 0; }
int ptr_frame_height(const PtrFrame *frame) { return frame ? frame->height : 0; }
int ptr_frame_channels(const PtrFrame *frame) { return frame ? frame->channels : 0; }
const float *ptr_frame_pixels(const PtrFrame *frame)
{
    return !frame ? NULL : frame->rgba ? frame->rgba : frame->buffers.rgb;
}
const float *ptr_frame_albedo(const PtrFrame *frame) { return frame ? frame->buffers.albedo : NULL; }
const float *ptr_frame_normal(const PtrFrame *frame) { return frame ? frame->buffers.normal : NULL; }

PtrStatus ptr_frame_new(int width, int height, int channels, const float *pixels,
                        PtrFrame **out, PtrErrorInfo *err)
{
    PtrError e;
    if (!pixels || !out)
        return ptr_api_usage(err, "frame: pixels and out are needed, not NULL");
    if (width < 1 || height < 1 || width > PTR_MAX_IMAGE_SIZE || height > PTR_MAX_IMAGE_SIZE ||
        (channels != 3 && channels != 4)) {
        ptr_error_set(&e, PTR_ERR_USAGE, "a frame of %dx%d pixels of %d channels: 1 to %d "
                      "pixels a side, 3 or 4 channels", width, height, channels,
                      PTR_MAX_IMAGE_SIZE);
        return ptr_api_fail(err, &e);
    }
    const size_t pixel_count = (size_t)width * (size_t)height;
    PtrFrame *f = calloc(1, sizeof *f);
    if (f) {
        f->buffers.rgb = malloc(pixel_count * 3 * sizeof *f->buffers.rgb);
        f->scene_name = strdup("");
    }
    if (f && channels == 4) {
        f->buffers.alpha = malloc(pixel_count * sizeof *f->buffers.alpha);
        f->rgba = malloc(pixel_count * 4 * sizeof *f->rgba);
    }
    if (!f || !f->buffers.rgb || !f->scene_name ||
        (channels == 4 && (!f->buffers.alpha || !f->rgba))) {
        ptr_frame_free(f);
        ptr_error_set(&e, PTR_ERR_NOMEM, "a frame of %dx%d pixels: out of memory", width,
                      height);
        return ptr_api_fail(err, &e);
    }
    for (size_t p = 0; p < pixel_count; p++) {
        memcpy(&f->buffers.rgb[3 * p], &pixels[channels * p], 3 * sizeof *pixels);
        if (channels == 4)
            f->buffers.alpha[p] = pixels[4 * p + 3];
    }
    if (channels == 4)
        memcpy(f->rgba, pixels, pixel_count * 4 * sizeof *pixels);
    f->width = width;
    f->height = height;
    f->channels = channels;
    f->info = (PtrOutputInfo){
        .scene_path = f->scene_name, .kernel = "", .accel = "",
        .sampler = ptr_sampler_name(PTR_SAMPLER_SOBOL), .alpha = f->buffers.alpha,
    };
    *out = f;
    return PTR_STATUS_OK;
}

PtrStatus ptr_frame_save(PtrContext *context, const char *path, const PtrFrame *frame,
                         const char *view, PtrErrorInfo *err)
{
    PtrError e;
    if (!context || !path || !frame)
        return ptr_api_usage(err, "save: context, path and frame are needed, not NULL");
    const int exr = ptr_image_is_exr(path);
    PtrOutputInfo info = frame->info;
    info.color = context->color;
    /* Only EXR names its channels: the passes go nowhere else. */
    if (!exr)
        info.albedo = info.normal = info.sample_counts = NULL;
    const PtrImageLayout layout = { frame->width, frame->height, 0, 0, frame->width,
                                    frame->height };
    if (ptr_output_check(context->images, path, PTR_DEPTH_DEFAULT, info.alpha != NULL, 0, &e) !=
            PTR_OK ||
        ptr_color_select(context->color, NULL, view, NULL, 0.0f, &e) != PTR_OK ||
        ptr_output_write(context->images, path, &layout, frame->buffers.rgb, &info, &e) != PTR_OK)
        return ptr_api_fail(err, &e);
    return PTR_STATUS_OK;
}

void ptr_frame_free(PtrFrame *frame)
{
    if (!frame)
        return;
    ptr_frame_buffers_free(&frame->buffers);
    free(frame->rgba);
    free(frame->scene_name);
    free(frame);
}
