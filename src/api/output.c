#include "api/output.h"

#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#include "base/cpu.h"
#include "base/version.h"
#include "image/image.h"

/* The formats ptr names in its usage, and the depths each can store, the
 * first its default. OpenImageIO writes all of them (they are among its
 * required dependencies), so an output in one of them is checked without
 * waiting for the library to load; any other extension (.bmp, .tga, ...) is
 * asked of the library, and takes 8 bits only. */
typedef struct Format {
    const char *extension;
    PtrDepth depths[4];
    int alpha; /* can store an alpha channel */
} Format;

static const Format formats[] = {
    { ".exr", { PTR_DEPTH_FLOAT, PTR_DEPTH_HALF }, 1 },
    { ".hdr", { PTR_DEPTH_FLOAT }, 0 },
    { ".png", { PTR_DEPTH_8, PTR_DEPTH_16 }, 1 },
    { ".jpg", { PTR_DEPTH_8 }, 0 },
    { ".jpeg", { PTR_DEPTH_8 }, 0 },
    { ".tif", { PTR_DEPTH_8, PTR_DEPTH_16, PTR_DEPTH_HALF, PTR_DEPTH_FLOAT }, 1 },
    { ".tiff", { PTR_DEPTH_8, PTR_DEPTH_16, PTR_DEPTH_HALF, PTR_DEPTH_FLOAT }, 1 },
};

/* The entry for path's extension, or NULL. */
static const Format *find_format(const char *path)
{
    const char *dot = strrchr(path, '.');
    for (size_t f = 0; dot && f < sizeof formats / sizeof formats[0]; f++)
        if (!strcasecmp(dot, formats[f].extension))
            return &formats[f];
    return NULL;
}

static const char *const depth_names[] = { "default", "8", "16", "half", "float" };

PtrResult ptr_depth_parse(const char *text, PtrDepth *depth, PtrError *err)
{
    for (int d = PTR_DEPTH_8; d <= PTR_DEPTH_FLOAT; d++)
        if (!strcmp(text, depth_names[d])) {
            *depth = (PtrDepth)d;
            return PTR_OK;
        }
    return ptr_error_set(err, PTR_ERR_USAGE, "'%s' is not 8, 16, half or float", text);
}

int ptr_exposure_ok(double stops)
{
    return fabs(stops) <= 64; /* NaN too is refused */
}

/* The depth a file gets, or PTR_DEPTH_DEFAULT if its format cannot store the
 * one asked for. */
static PtrDepth resolve_depth(const char *path, PtrDepth wanted)
{
    const Format *format = find_format(path);
    if (format) {
        if (wanted == PTR_DEPTH_DEFAULT)
            return format->depths[0];
        for (int i = 0; i < 4; i++)
            if (format->depths[i] == wanted)
                return wanted;
        return PTR_DEPTH_DEFAULT;
    }
    return wanted == PTR_DEPTH_DEFAULT || wanted == PTR_DEPTH_8 ? PTR_DEPTH_8 : PTR_DEPTH_DEFAULT;
}

PtrResult ptr_output_check(PtrImageLoader *images, const char *path, PtrDepth depth, int alpha,
                           int passes, PtrError *err)
{
    const Format *format = find_format(path);
    int known = format != NULL;
    if (alpha && !(format && format->alpha))
        return ptr_error_set(err, PTR_ERR_USAGE,
                             "%s: a transparent image (--transparent) needs a format with "
                             "alpha: .exr, .png or .tif",
                             path);
    /* Only EXR names its channels: the passes go nowhere else. */
    if (passes && !ptr_image_is_exr(path))
        return ptr_error_set(err, PTR_ERR_USAGE,
                             "%s: the passes (--passes) are written as layers of an EXR: use .exr",
                             path);
    PtrResult ready = known ? PTR_OK : ptr_image_ready(images, err);
    if (ready != PTR_OK)
        return ready;
    if (!known && !ptr_image_can_write(images, path))
        return ptr_error_set(err, PTR_ERR_USAGE,
                             "%s: no image format for this extension (try .exr or .png)", path);
    if (resolve_depth(path, depth) == PTR_DEPTH_DEFAULT)
        return ptr_error_set(err, PTR_ERR_USAGE, "%s: this format cannot store --depth %s", path,
                             depth_names[depth]);
    /* The file is written beside its final name and renamed, so the folder
     * must take new files. */
    char dir[4096];
    const char *slash = strrchr(path, '/');
    size_t len = slash ? (size_t)(slash - path) : 1;
    if (len >= sizeof dir)
        return ptr_error_set(err, PTR_ERR_OUTPUT, "%s: path too long", path);
    memcpy(dir, slash ? path : ".", len);
    dir[len] = '\0';
    if (slash && len == 0)
        strcpy(dir, "/");
    struct stat st;
    if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode))
        return ptr_error_set(err, PTR_ERR_OUTPUT, "%s: folder %s does not exist", path, dir);
    if (access(dir, W_OK | X_OK) != 0)
        return ptr_error_set(err, PTR_ERR_OUTPUT, "%s: cannot create files in %s: %s", path, dir,
                             strerror(errno));
    if (stat(path, &st) == 0 && S_ISDIR(st.st_mode))
        return ptr_error_set(err, PTR_ERR_OUTPUT, "%s: is a directory", path);
    return PTR_OK;
}

/* Premultiplies rgb by alpha, or divides it by alpha (where alpha is 0,
 * premultiplied colour is 0 and stays so); nothing if alpha is NULL. */
static void scale_by_alpha(float *rgb, const float *alpha, size_t pixels, int premultiply)
{
    for (size_t p = 0; alpha && p < pixels; p++)
        for (int c = 0; c < 3 && alpha[p] > 0.0f; c++)
            rgb[3 * p + c] = premultiply ? rgb[3 * p + c] * alpha[p] : rgb[3 * p + c] / alpha[p];
}

/* The premultiplied colour is what the network takes: where camera rays
 * met nothing it adds nothing, as a black background would. Where no camera
 * ray met anything (alpha 0), the colour stays 0: the network's blur must
 * not put light where the image holds nothing to composite. */
PtrResult ptr_output_denoise(const char *path, const PtrImageLayout *layout, const float *rgb,
                             const PtrOutputInfo *info, float **out, PtrError *err)
{
    size_t pixels = (size_t)layout->width * (size_t)layout->height;
    float *denoised = malloc(pixels * 3 * sizeof *denoised);
    if (!denoised)
        return ptr_error_set(err, PTR_ERR_NOMEM, "%s: out of memory", path);
    const PtrDenoiseInput input = {
        .color = rgb, .albedo = info->albedo, .normal = info->normal,
        .color_stride = 3, .albedo_stride = 3, .normal_stride = 3,
        .width = (size_t)layout->width, .height = (size_t)layout->height,
    };
    int threads = ptr_thread_count(info->threads);
    PtrError problem;
    PtrResult res = ptr_denoise(info->denoiser, &input, threads, denoised, 3, &problem);
    if (res != PTR_OK) {
        free(denoised);
        return ptr_error_set(err, res, "%s: %s", path, problem.message);
    }
    for (size_t p = 0; info->alpha && p < pixels; p++)
        for (int c = 0; c < 3 && info->alpha[p] == 0.0f; c++)
            denoised[3 * p + c] = 0.0f;
    *out = denoised;
    return PTR_OK;
}

PtrResult ptr_output_write(PtrImageLoader *images, const char *path, const PtrImageLayout *layout,
                           const float *rgb, const PtrOutputInfo *info, PtrError *err)
{
    const PtrOutputSettings *output = &info->output;
    PtrDepth depth = resolve_depth(path, output->depth);
    int is_float = depth == PTR_DEPTH_HALF || depth == PTR_DEPTH_FLOAT;
    int display_referred = !is_float || output->bake_view;
    size_t pixels = (size_t)layout->width * (size_t)layout->height;

    /* From here on rgb is the colour the file shows; an EXR keeps the noisy
     * one beside it. */
    const float *noisy = info->noisy;
    float *denoised = NULL;
    if (info->denoiser) {
        if (!info->albedo || !info->normal)
            return ptr_error_set(err, PTR_ERR_INTERNAL, "%s: a denoiser without the passes",
                                 path);
        PtrResult res = ptr_output_denoise(path, layout, rgb, info, &denoised, err);
        if (res != PTR_OK)
            return res;
        noisy = rgb;
        rgb = denoised;
    }

    const float *alpha = info->alpha;
    int straight = alpha && !ptr_image_is_exr(path);
    float *viewed = NULL;
    if (display_referred || straight) {
        viewed = malloc(pixels * 3 * sizeof *viewed);
        if (!viewed) {
            free(denoised);
            return ptr_error_set(err, PTR_ERR_NOMEM, "%s: out of memory", path);
        }
        memcpy(viewed, rgb, pixels * 3 * sizeof *viewed);
        scale_by_alpha(viewed, alpha, pixels, 0);
        PtrError color_err;
        if (display_referred && ptr_color_apply(output->color, viewed, pixels, &color_err) != PTR_OK) {
            free(viewed);
            free(denoised);
            return ptr_error_set(err, color_err.code, "%s: %s", path, color_err.message);
        }
        if (!straight)
            scale_by_alpha(viewed, alpha, pixels, 1);
    }

    char seed[24], exposure[32], hash[24], spheres[24], threshold[32];
    snprintf(spheres, sizeof spheres, "%zu", info->spheres);
    snprintf(threshold, sizeof threshold, "%g", info->noise_threshold);
    snprintf(seed, sizeof seed, "%" PRIu64, info->seed);
    snprintf(hash, sizeof hash, "%016" PRIx64, info->scene_hash);
    snprintf(exposure, sizeof exposure, "%g", output->exposure);
    const char *space = display_referred ? ptr_color_view_space(output->color) : "lin_rec709";
    const PtrImageAttr attrs[] = {
        { .name = "Software", .type = PTR_ATTR_STRING, .string_value = "ptr " PTR_VERSION },
        { .name = "oiio:ColorSpace", .type = PTR_ATTR_STRING, .string_value = space },
        /* OpenImageIO reads every EXR back as "Linear": say it where it stays. */
        { .name = "ptr:colorspace", .type = PTR_ATTR_STRING, .string_value = space },
        { .name = "ptr:scene", .type = PTR_ATTR_STRING, .string_value = info->scene_path },
        { .name = info->legacy_scene_hash ? "ptr:scene_hash" : "ptr:scene_xxh3",
          .type = PTR_ATTR_STRING, .string_value = hash },
        { .name = "ptr:samples", .type = PTR_ATTR_INT, .int_value = (int)info->samples },
        { .name = "ptr:sample_first", .type = PTR_ATTR_INT, .int_value = (int)info->sample_first },
        { .name = "ptr:interrupted", .type = PTR_ATTR_INT, .int_value = info->interrupted },
        { .name = "ptr:seed", .type = PTR_ATTR_STRING, .string_value = seed },
        { .name = "ptr:max_depth", .type = PTR_ATTR_INT, .int_value = info->max_depth },
        { .name = "ptr:kernel", .type = PTR_ATTR_STRING, .string_value = info->kernel },
        { .name = "ptr:accel", .type = PTR_ATTR_STRING, .string_value = info->accel },
        { .name = "ptr:spheres", .type = PTR_ATTR_STRING, .string_value = spheres },
        { .name = "ptr:import_seconds", .type = PTR_ATTR_FLOAT,
          .float_value = (float)info->import_seconds },
        { .name = "ptr:build_seconds", .type = PTR_ATTR_FLOAT,
          .float_value = (float)info->build_seconds },
        { .name = "ptr:sampler", .type = PTR_ATTR_STRING, .string_value = info->sampler },
        { .name = "ptr:direct_lighting", .type = PTR_ATTR_STRING,
          .string_value = info->direct_lighting ? "on" : "off" },
        { .name = "ptr:noise_threshold", .type = PTR_ATTR_STRING, .string_value = threshold },
        { .name = "ptr:min_samples", .type = PTR_ATTR_INT, .int_value = (int)info->min_samples },
        { .name = "ptr:render_seconds", .type = PTR_ATTR_FLOAT,
          .float_value = (float)info->render_seconds },
        { .name = "ptr:ocio_config", .type = PTR_ATTR_STRING,
          .string_value = ptr_color_source(output->color) },
        /* What the pixels went through (when display-referred) or would go
         * through to be seen as intended. */
        { .name = "ptr:display", .type = PTR_ATTR_STRING, .string_value = ptr_color_display(output->color) },
        { .name = "ptr:view", .type = PTR_ATTR_STRING, .string_value = ptr_color_view(output->color) },
        { .name = "ptr:look", .type = PTR_ATTR_STRING, .string_value = ptr_color_look(output->color) },
        { .name = "ptr:exposure", .type = PTR_ATTR_STRING, .string_value = exposure },
        { .name = "oiio:dither", .type = PTR_ATTR_INT, .int_value = output->dither ? 1 : 0 },
        /* Last, and only in a denoised image's header: the others' stay as
         * they were. */
        { .name = "ptr:denoised", .type = PTR_ATTR_STRING, .string_value = info->denoise_quality },
    };
    const size_t attr_count = sizeof attrs / sizeof attrs[0] - (noisy ? 0 : 1);
    static const PtrPixelFormat pixel_formats[] = {
        [PTR_DEPTH_8] = PTR_PIXEL_UINT8, [PTR_DEPTH_16] = PTR_PIXEL_UINT16,
        [PTR_DEPTH_HALF] = PTR_PIXEL_HALF, [PTR_DEPTH_FLOAT] = PTR_PIXEL_FLOAT,
    };
    const PtrImageExtras extras = { info->sample_counts, info->albedo, info->normal, noisy };
    PtrResult res = ptr_image_write(images, path, layout, viewed ? viewed : rgb, alpha,
                                    &extras, pixel_formats[depth], attrs, attr_count, err);
    free(viewed);
    free(denoised);
    return res;
}
