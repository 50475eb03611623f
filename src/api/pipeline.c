#include "api/pipeline.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The import's texture decoder (PtrTextureDecoder): through the loader,
 * context; alpha 1 where the image has none. */
static PtrResult decode_texture(void *context, const char *name, const unsigned char *bytes,
                                size_t size, PtrTexels *out, PtrError *err)
{
    PtrImage *image;
    PtrResult res = ptr_image_decode(context, name, bytes, size, &image, err);
    if (res != PTR_OK)
        return res;
    const size_t pixels = (size_t)ptr_image_width(image) * (size_t)ptr_image_height(image);
    out->rgba = malloc((pixels ? pixels : 1) * 4 * sizeof *out->rgba);
    if (!out->rgba) {
        ptr_image_free(image);
        return ptr_error_set(err, PTR_ERR_NOMEM, "%s: out of memory", name);
    }
    const float *rgb = ptr_image_pixels(image), *alpha = ptr_image_alpha(image);
    for (size_t p = 0; p < pixels; p++) {
        memcpy(&out->rgba[4 * p], &rgb[3 * p], 3 * sizeof *rgb);
        out->rgba[4 * p + 3] = alpha ? alpha[p] : 1.0f;
    }
    out->width = ptr_image_width(image);
    out->height = ptr_image_height(image);
    out->bits_per_channel = ptr_image_bits_per_channel(image);
    ptr_image_free(image);
    return PTR_OK;
}

static const struct {
    uint64_t lo, hi;
    const char *words;
} number_ranges[] = {
    [PTR_NUMBER_SIZE] = { 1, PTR_MAX_IMAGE_SIZE, "a whole number from 1 to 65536" },
    [PTR_NUMBER_SAMPLES] = { 1, 1u << 30, "a whole number from 1 to 2^30" },
    [PTR_NUMBER_MIN_SAMPLES] = { 2, 1u << 30, "a whole number from 2 to 2^30" },
    [PTR_NUMBER_MAX_DEPTH] = { 1, 100000, "a whole number from 1 to 100000" },
    /* Beyond this, a mistake: threads are started, and kept, for every one. */
    [PTR_NUMBER_THREADS] = { 0, 1024, "a whole number from 0 to 1024" },
};
_Static_assert(PTR_MAX_IMAGE_SIZE == 65536, "number_ranges' words");

int ptr_render_number_ok(PtrRenderNumber number, uint64_t value)
{
    return value >= number_ranges[number].lo && value <= number_ranges[number].hi;
}

const char *ptr_render_number_range(PtrRenderNumber number)
{
    return number_ranges[number].words;
}

int ptr_noise_threshold_ok(double threshold)
{
    return threshold > 0 && threshold <= 1e6;
}

int ptr_region_ok(PtrRegion r)
{
    return r.x0 >= 0 && r.y0 >= 0 && r.x1 > r.x0 && r.y1 > r.y0;
}

int ptr_time_budget_ok(double seconds)
{
    return seconds > 0 && seconds <= 1e7;
}

const char *ptr_sample_range_problem(float noise_threshold, uint64_t first_sample,
                                     uint64_t samples)
{
    if (first_sample + samples > number_ranges[PTR_NUMBER_SAMPLES].hi)
        return "the samples end past 2^30";
    /* Stopping decisions need every sample of a pixel from the first on; a
     * later range cannot know them. */
    if (noise_threshold > 0 && first_sample > 0)
        return "a noise threshold needs samples from 0, not from a later first sample";
    return NULL;
}

PtrTextureDecoder ptr_texture_decoder(PtrImageLoader *images)
{
    return (PtrTextureDecoder){ decode_texture, images };
}

void ptr_choose_size(const PtrScene *scene, const PtrCamera *camera, int width, int height,
                     int divisor, int *out_width, int *out_height)
{
    float aspect = camera->aspect > 0.0f ? camera->aspect
                   : scene->width > 0    ? (float)scene->width / (float)scene->height
                                         : 16.0f / 9.0f;
    int w = width, h = height;
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
    w /= divisor;
    h /= divisor;
    *out_width = w < 1 ? 1 : w > PTR_MAX_IMAGE_SIZE ? PTR_MAX_IMAGE_SIZE : w;
    *out_height = h < 1 ? 1 : h > PTR_MAX_IMAGE_SIZE ? PTR_MAX_IMAGE_SIZE : h;
}

PtrResult ptr_prepare_render(PtrScene *scene, PtrKernel kernel, PtrCpuLevel level,
                             PtrIntegrator integrator, PtrAccelChoice accel, int threads,
                             const char *name, PtrPrepared *out, PtrError *err)
{
    PtrResult res = ptr_isect_init(&out->isect, kernel, level, scene->spheres.count, err);
    if (res != PTR_OK)
        return res;
    out->integrator = ptr_integrator_resolve(integrator, level);
    /* Before the build, which reorders the spheres and frees the ids that
     * give the file's order, which the hash takes. */
    PtrError problem;
    res = ptr_scene_hash(scene, &out->scene_hash, &problem);
    if (res != PTR_OK)
        return ptr_error_set(err, res, "%s: %s", name, problem.message);
    res = ptr_accel_init(&out->accel, accel, &out->isect,
                         out->integrator == PTR_INTEGRATOR_BUNDLES, scene, threads, &problem);
    if (res != PTR_OK)
        return ptr_error_set(err, res, "%s: cannot build the tree over %zu spheres: %s", name,
                             scene->spheres.count, problem.message);
    return PTR_OK;
}

void ptr_prepared_free(PtrPrepared *prepared)
{
    ptr_accel_free(&prepared->accel);
}

void ptr_frame_buffers_free(PtrFrameBuffers *buffers)
{
    free(buffers->rgb);
    free(buffers->alpha);
    free(buffers->sample_counts);
    free(buffers->albedo);
    free(buffers->normal);
    *buffers = (PtrFrameBuffers){ 0 };
}

PtrResult ptr_render_frame(const PtrScene *scene, const PtrAccel *accel,
                           const PtrRenderSettings *settings, const PtrProgressiveOptions *passes,
                           const char *name, PtrFrameBuffers *out, PtrProgressiveResult *done,
                           PtrError *err)
{
    PtrRegion region = ptr_render_region(settings);
    size_t pixels = (size_t)(region.x1 - region.x0) * (size_t)(region.y1 - region.y0);
    int counts = settings->noise_threshold > 0;
    PtrFrameBuffers b = {
        .rgb = malloc(pixels * 3 * sizeof *b.rgb),
        .alpha = settings->transparent ? malloc(pixels * sizeof *b.alpha) : NULL,
        .sample_counts = counts ? malloc(pixels * sizeof *b.sample_counts) : NULL,
        .albedo = settings->passes ? malloc(pixels * 3 * sizeof *b.albedo) : NULL,
        .normal = settings->passes ? malloc(pixels * 3 * sizeof *b.normal) : NULL,
    };
    if (!b.rgb || (settings->transparent && !b.alpha) || (counts && !b.sample_counts) ||
        (settings->passes && (!b.albedo || !b.normal))) {
        ptr_frame_buffers_free(&b);
        return ptr_error_set(err, PTR_ERR_NOMEM, "%s: cannot allocate a %dx%d image", name,
                             region.x1 - region.x0, region.y1 - region.y0);
    }
    PtrError problem;
    PtrResult res = ptr_render_progressive(scene, accel, settings, passes, b.rgb, b.alpha,
                                           b.sample_counts, b.albedo, b.normal, done, &problem);
    if (res != PTR_OK) {
        ptr_frame_buffers_free(&b);
        /* The renderer does not know where the scene came from. */
        return res == PTR_ERR_SCENE_INVALID
                   ? ptr_error_set(err, res, "%s: %s", name, problem.message)
                   : ptr_error_set(err, res, "%s", problem.message);
    }
    *out = b;
    return PTR_OK;
}
