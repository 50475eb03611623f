/* The public API's renders and frames (include/ptr/ptr.h), over the
 * entries the command line renders and writes through (api_internal.h). */
#include <signal.h>
#include <stdlib.h>
#include <string.h>

#include "api/api_internal.h"
#include "api/output.h"
#include "builder.h"

/* What a render's options choose beyond the request: the sky and the
 * denoiser, which the request points to. */
typedef struct Choices {
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

/* The request the options make, read and checked (its sky, camera and
 * denoiser left for the render to point to). */
static PtrResult read_request(const PtrContext *context, const PtrRenderOptions *o,
                              PtrRenderRequest *r, Choices *c, PtrError *err)
{
    PtrError problem;
    *c = (Choices){ 0 };
    *r = (PtrRenderRequest){
        .width = o->width, .height = o->height, .divisor = 1,
        .first_sample = o->first_sample, .samples = o->samples, .seed = o->seed,
        .max_depth = o->max_depth, .threads = o->threads ? o->threads : context->threads,
        .level = context->cpu_level, .direct_lighting = o->direct_lighting ? PTR_ON : PTR_OFF,
        .noise_threshold = o->noise_threshold, .min_samples = o->min_samples,
        .transparent = o->transparent, .passes = o->passes,
        .region = { o->region[0], o->region[1], o->region[2], o->region[3] },
        .time_budget = o->time_budget,
    };
    if (o->kernel && strcmp(o->kernel, "c") && strcmp(o->kernel, "asm"))
        return ptr_error_set(err, PTR_ERR_USAGE, "kernel: '%s' is not c or asm", o->kernel);
    r->kernel = !o->kernel ? PTR_KERNEL_AUTO : o->kernel[0] == 'c' ? PTR_KERNEL_C : PTR_KERNEL_ASM;
    PtrCpuLevel cap;
    if (o->cpu_cap && ptr_cpu_parse_level(o->cpu_cap, &cap, &problem) != PTR_OK)
        return option_error("cpu_cap", &problem, err);
    if (o->cpu_cap && cap < r->level)
        r->level = cap;
    if (o->integrator && ptr_integrator_parse(o->integrator, &r->integrator, &problem) != PTR_OK)
        return option_error("integrator", &problem, err);
    if (!ptr_integrator_available(r->integrator, r->level))
        return ptr_error_set(err, PTR_ERR_USAGE, "integrator: %s is not available at CPU level %s",
                             ptr_integrator_name(r->integrator), ptr_cpu_level_name(r->level));
    if (o->accel && ptr_accel_parse(o->accel, &r->accel, &problem) != PTR_OK)
        return option_error("accel", &problem, err);
    if (o->sampler && ptr_sampler_parse(o->sampler, &r->sampler, &problem) != PTR_OK)
        return option_error("sampler", &problem, err);
    c->has_sky = o->sky != NULL;
    if (o->sky && ptr_sky_parse(o->sky, &c->sky, &problem) != PTR_OK)
        return option_error("sky", &problem, err);
    c->denoise = o->denoise != NULL;
    if (o->denoise && ptr_denoise_quality_parse(o->denoise, &c->denoise_quality, &problem) != PTR_OK)
        return option_error("denoise", &problem, err);
    /* The name, not the caller's string: the frame keeps it for its save. */
    r->denoise_quality = c->denoise ? ptr_denoise_quality_name(c->denoise_quality) : NULL;
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
    const PtrRegion whole = { 0 };
    if (memcmp(&r->region, &whole, sizeof whole) && !ptr_region_ok(r->region))
        return ptr_error_set(err, PTR_ERR_USAGE, "region: %d,%d,%d,%d is not " PTR_REGION_WORDS,
                             r->region.x0, r->region.y0, r->region.x1, r->region.y1);
    if (o->time_budget != 0 && !ptr_time_budget_ok(o->time_budget))
        return ptr_error_set(err, PTR_ERR_USAGE,
                             "time_budget: %g is not 0 (none) or above 0 and at most 10^7",
                             o->time_budget);
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

/* The scene's kernels and tree for this request, built unless already. */
static PtrResult prepare(PtrSceneHandle *h, const PtrRenderRequest *r, PtrError *err)
{
    const PtrPreparedFor wanted = { r->kernel, r->level, r->integrator, r->accel };
    if (h->prepared_valid && !memcmp(&wanted, &h->prepared_for, sizeof wanted))
        return PTR_OK;
    if (h->prepared_valid)
        ptr_prepared_free(&h->prepared);
    h->prepared_valid = 0;
    PtrResult res = ptr_prepare_render(&h->scene, r->kernel, r->level, r->integrator, r->accel,
                                       r->threads, h->name, &h->prepared, err);
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

/* The settings of the request for the scene at the size chosen. */
static PtrRenderSettings settings_for(const PtrSceneHandle *h, const PtrRenderRequest *r,
                                      int width, int height)
{
    return (PtrRenderSettings){
        .width = width, .height = height, .region = r->region, .seed = r->seed,
        .max_depth = r->max_depth, .threads = r->threads, .sampler = r->sampler,
        .direct_lighting = r->direct_lighting, .noise_threshold = r->noise_threshold,
        .min_samples = r->min_samples, .integrator = h->prepared.integrator,
        .transparent = r->transparent,
        .passes = r->passes || r->denoiser, /* the denoiser's guides */
    };
}

/* Renders into f at the size chosen, the scene's tree ready, with this
 * render's sky and camera in the scene; PTR_ERR_USAGE if the region lies
 * outside the image. */
static PtrResult render_into(PtrSceneHandle *h, const PtrRenderRequest *r, int width,
                             int height, const PtrRenderHooks *hooks, PtrFrame *f, PtrError *err)
{
    const PtrRenderSettings settings = settings_for(h, r, width, height);
    const PtrRegion region = ptr_render_region(&settings);
    if (region.x1 == 0)
        return ptr_error_set(err, PTR_ERR_USAGE, "region %d,%d,%d,%d lies outside the %dx%d image",
                             r->region.x0, r->region.y0, r->region.x1, r->region.y1, width,
                             height);
    f->layout = (PtrImageLayout){ region.x1 - region.x0, region.y1 - region.y0, region.x0,
                                  region.y0, settings.width, settings.height };
    f->channels = r->transparent ? 4 : 3;
    PtrProgressiveOptions passes = {
        .first_sample = r->first_sample, .samples = r->samples, .time_budget = r->time_budget,
        .stop = hooks->stop, .report = hooks->report, .user = hooks->user,
    };
    const PtrAccel *accel = &h->prepared.accel;
    if (hooks->begin)
        hooks->begin(hooks->begin_user, &h->scene, accel, &settings, &passes);
    PtrResult res = ptr_render_frame(&h->scene, accel, &settings, &passes, h->name, &f->buffers,
                                     &f->done, err);
    if (res != PTR_OK)
        return res;
    f->info = (PtrOutputInfo){
        .scene_path = f->scene_name, .scene_hash = h->prepared.scene_hash,
        .kernel = accel->isect.name, .accel = ptr_accel_name(accel),
        .spheres = h->scene.spheres.count, .import_seconds = h->import_seconds,
        .build_seconds = accel->build_seconds, .sample_first = r->first_sample,
        .samples = f->done.samples_done, .interrupted = f->done.stopped, .seed = r->seed,
        .max_depth = r->max_depth, .sampler = ptr_sampler_name(r->sampler),
        .direct_lighting = r->direct_lighting == PTR_ON,
        .noise_threshold = r->noise_threshold, .min_samples = r->min_samples,
        .sample_counts = f->buffers.sample_counts, .albedo = f->buffers.albedo,
        .normal = f->buffers.normal, .alpha = f->buffers.alpha, .denoiser = r->denoiser,
        .denoise_quality = r->denoise_quality, .threads = r->threads,
        .render_seconds = f->done.stats.seconds,
    };
    return PTR_OK;
}

PtrResult ptr_api_render(PtrSceneHandle *h, const PtrRenderRequest *r,
                         const PtrRenderHooks *hooks, int *width, int *height, PtrFrame **out,
                         PtrError *err)
{
    /* The size before anything can fail, from this render's camera, which
     * takes the scene's place only after the build (the scene's hash is of
     * its own). */
    ptr_choose_size(&h->scene, r->camera ? r->camera : &h->scene.camera, r->width, r->height,
                    r->divisor, width, height);
    PtrResult res = prepare(h, r, err);
    if (res != PTR_OK)
        return res;
    PtrFrame *f = calloc(1, sizeof *f);
    if (!f || !(f->scene_name = strdup(h->name))) {
        free(f);
        return ptr_error_set(err, PTR_ERR_NOMEM, "%s: out of memory", h->name);
    }
    /* This render's sky and camera, the scene's own kept for the next. */
    const PtrSky sky = h->scene.sky;
    const PtrCamera camera = h->scene.camera;
    if (r->sky)
        h->scene.sky = *r->sky;
    if (r->camera)
        h->scene.camera = *r->camera;
    res = render_into(h, r, *width, *height, hooks, f, err);
    /* Only what was changed: a live view may still be reading the scene. */
    if (r->sky)
        h->scene.sky = sky;
    if (r->camera)
        h->scene.camera = camera;
    if (res != PTR_OK) {
        ptr_frame_free(f);
        return res;
    }
    *out = f;
    return PTR_OK;
}

PtrResult ptr_api_frame_finish(PtrFrame *f, const char *name, PtrError *err)
{
    if (!f->info.denoiser)
        return PTR_OK;
    float *denoised;
    PtrResult res = ptr_output_denoise(name, &f->layout, f->buffers.rgb, &f->info,
                                       &denoised, err);
    if (res != PTR_OK)
        return res;
    f->noisy = f->buffers.rgb;
    f->buffers.rgb = denoised;
    f->info.noisy = f->noisy;
    f->info.denoiser = NULL; /* saved as it is: it is denoised already */
    return PTR_OK;
}

PtrResult ptr_api_frame_write(PtrImageLoader *images, const char *path, const PtrFrame *frame,
                              const PtrOutputSettings *output, PtrError *err)
{
    PtrOutputInfo info = frame->info;
    info.output = *output;
    return ptr_output_write(images, path, &frame->layout, frame->buffers.rgb, &info, err);
}

/* The frame's colour with alpha, for ptr_frame_pixels, with a transparent
 * background. */
static PtrResult make_rgba(PtrFrame *f, PtrError *err)
{
    if (!f->buffers.alpha)
        return PTR_OK;
    const size_t pixels = (size_t)f->layout.width * (size_t)f->layout.height;
    f->rgba = malloc(pixels * 4 * sizeof *f->rgba);
    if (!f->rgba)
        return ptr_error_set(err, PTR_ERR_NOMEM, "%s: out of memory", f->scene_name);
    for (size_t p = 0; p < pixels; p++) {
        memcpy(&f->rgba[4 * p], &f->buffers.rgb[3 * p], 3 * sizeof *f->rgba);
        f->rgba[4 * p + 3] = f->buffers.alpha[p];
    }
    return PTR_OK;
}

/* Renders into a new frame as the options say, read into request and
 * choices: cancelled by progress, finished and with its RGBA. */
static PtrResult render(PtrContext *context, PtrSceneHandle *h, const PtrRenderOptions *o,
                        PtrRenderRequest *request, const Choices *c, Progress *progress,
                        PtrFrame **out, PtrError *err)
{
    if (c->denoise) {
        PtrResult res = denoiser(context, c->denoise_quality, err);
        if (res != PTR_OK)
            return res;
        request->denoiser = context->denoisers[c->denoise_quality];
    }
    PtrCamera camera;
    if (o->camera) {
        PtrResult res = camera_at(o->camera, h->scene.origin, &camera, err);
        if (res != PTR_OK)
            return res;
        request->camera = &camera;
    }
    if (c->has_sky)
        request->sky = &c->sky;
    const PtrRenderHooks hooks = {
        .stop = &progress->stop, .report = progress->callback ? report_progress : NULL,
        .user = progress,
    };
    int width, height; /* the frame's layout has them */
    PtrFrame *f;
    PtrResult res = ptr_api_render(h, request, &hooks, &width, &height, &f, err);
    if (res != PTR_OK)
        return res;
    if (f->done.stopped)
        res = ptr_error_set(err, PTR_ERR_INTERRUPTED, "%s: cancelled after %u of %u samples",
                            h->name, f->done.samples_done, o->samples);
    if (res == PTR_OK)
        res = ptr_api_frame_finish(f, f->scene_name, err);
    if (res == PTR_OK)
        res = make_rgba(f, err);
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
    PtrRenderRequest request;
    Choices choices;
    Progress progress = { callback, user, 0 };
    if (!context || !scene || !options || !out)
        return ptr_api_usage(err, "render: context, scene, options and out are needed, not NULL");
    if (read_request(context, options, &request, &choices, &e) != PTR_OK ||
        render(context, scene, options, &request, &choices, &progress, out, &e) != PTR_OK)
        return ptr_api_fail(err, &e);
    return PTR_STATUS_OK;
}

int ptr_frame_width(const PtrFrame *frame) { return frame ? frame->layout.width : 0; }
int ptr_frame_height(const PtrFrame *frame) { return frame ? frame->layout.height : 0; }
int ptr_frame_channels(const PtrFrame *frame) { return frame ? frame->channels : 0; }
const float *ptr_frame_pixels(const PtrFrame *frame)
{
    return !frame ? NULL : frame->rgba ? frame->rgba : frame->buffers.rgb;
}
const float *ptr_frame_albedo(const PtrFrame *frame) { return frame ? frame->buffers.albedo : NULL; }
const float *ptr_frame_normal(const PtrFrame *frame) { return frame ? frame->buffers.normal : NULL; }
const float *ptr_frame_noisy(const PtrFrame *frame) { return frame ? frame->noisy : NULL; }
uint32_t ptr_frame_samples(const PtrFrame *frame) { return frame ? frame->info.samples : 0; }

void ptr_frame_placement(const PtrFrame *frame, int *x, int *y, int *image_width,
                         int *image_height)
{
    const PtrImageLayout none = { 0 }, *layout = frame ? &frame->layout : &none;
    if (x)
        *x = layout->x;
    if (y)
        *y = layout->y;
    if (image_width)
        *image_width = layout->full_width;
    if (image_height)
        *image_height = layout->full_height;
}

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
    f->layout = (PtrImageLayout){ width, height, 0, 0, width, height };
    f->channels = channels;
    f->info = (PtrOutputInfo){
        .scene_path = f->scene_name, .kernel = "", .accel = "",
        .sampler = ptr_sampler_name(PTR_SAMPLER_SOBOL), .alpha = f->buffers.alpha,
    };
    *out = f;
    return PTR_STATUS_OK;
}

PtrStatus ptr_frame_set_placement(PtrFrame *frame, int x, int y, int image_width,
                                  int image_height, PtrErrorInfo *err)
{
    PtrError e;
    if (!frame)
        return ptr_api_usage(err, "placement: frame is needed, not NULL");
    PtrImageLayout *layout = &frame->layout;
    /* In long long: x + width cannot overflow. */
    if (x < 0 || y < 0 || (long long)x + layout->width > image_width ||
        (long long)y + layout->height > image_height || image_width > PTR_MAX_IMAGE_SIZE ||
        image_height > PTR_MAX_IMAGE_SIZE) {
        ptr_error_set(&e, PTR_ERR_USAGE, "placement: %dx%d pixels at %d,%d do not lie inside "
                      "an image of %dx%d of at most %d pixels a side", layout->width,
                      layout->height, x, y, image_width, image_height, PTR_MAX_IMAGE_SIZE);
        return ptr_api_fail(err, &e);
    }
    layout->x = x;
    layout->y = y;
    layout->full_width = image_width;
    layout->full_height = image_height;
    return PTR_STATUS_OK;
}

/* The output's settings the save options give, read and checked, with
 * the context's colour configuration selected as they say. */
static PtrResult read_save_options(PtrContext *context, const PtrSaveOptions *o,
                                   PtrOutputSettings *output, PtrError *err)
{
    PtrError problem;
    *output = (PtrOutputSettings){ .depth = PTR_DEPTH_DEFAULT, .color = context->color,
                                   .exposure = o->exposure, .bake_view = o->bake_view != 0,
                                   .dither = o->dither != 0 };
    if (o->depth && ptr_depth_parse(o->depth, &output->depth, &problem) != PTR_OK)
        return option_error("depth", &problem, err);
    if (!ptr_exposure_ok(o->exposure))
        return ptr_error_set(err, PTR_ERR_USAGE, "exposure: %g is not a number of stops "
                             "from -64 to 64", (double)o->exposure);
    return ptr_color_select(context->color, o->display, o->view, o->look, o->exposure, err);
}

PtrStatus ptr_frame_save(PtrContext *context, const char *path, const PtrFrame *frame,
                         const PtrSaveOptions *options, PtrErrorInfo *err)
{
    PtrError e;
    const PtrSaveOptions defaults = { 0 };
    PtrOutputSettings output;
    if (!context || !path || !frame)
        return ptr_api_usage(err, "save: context, path and frame are needed, not NULL");
    if (read_save_options(context, options ? options : &defaults, &output, &e) != PTR_OK ||
        ptr_output_check(context->images, path, output.depth, frame->buffers.alpha != NULL, 0,
                         &e) != PTR_OK ||
        ptr_api_frame_write(context->images, path, frame, &output, &e) != PTR_OK)
        return ptr_api_fail(err, &e);
    return PTR_STATUS_OK;
}

void ptr_frame_free(PtrFrame *frame)
{
    if (!frame)
        return;
    ptr_frame_buffers_free(&frame->buffers);
    free(frame->noisy);
    free(frame->rgba);
    free(frame->scene_name);
    free(frame);
}
