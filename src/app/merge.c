#include "app/merge.h"

#include <inttypes.h>
#include <stdlib.h>
#include <string.h>

#include "api/output.h"
#include "base/cpu.h"
#include "image/image.h"

typedef struct Part {
    const char *path;
    PtrImage *image;
    PtrImageLayout layout;
    const char *scene, *hash, *seed;
    int legacy_hash; /* hash is ptr:scene_hash (see PtrOutputInfo) */
    const char *sampler, *direct_lighting, *noise_threshold;
    long first, samples, max_depth;
} Part;

static const char *required(const Part *p, const char *name, PtrError *err)
{
    const char *value = ptr_image_attr(p->image, name);
    if (!value)
        ptr_error_set(err, PTR_ERR_USAGE, "%s: no %s in the metadata: not a part written by ptr",
                      p->path, name);
    return value;
}

static PtrResult read_part(PtrImageLoader *images, Part *p, PtrError *err)
{
    PtrResult res = ptr_image_read(images, p->path, &p->image, err);
    if (res != PTR_OK)
        return res;
    p->layout = ptr_image_layout(p->image);
    const char *first, *samples, *depth, *space;
    p->legacy_hash = !ptr_image_attr(p->image, "ptr:scene_xxh3") &&
                     ptr_image_attr(p->image, "ptr:scene_hash");
    if (!(p->scene = required(p, "ptr:scene", err)) ||
        !(p->hash = required(p, p->legacy_hash ? "ptr:scene_hash" : "ptr:scene_xxh3", err)) ||
        !(p->seed = required(p, "ptr:seed", err)) || !required(p, "ptr:kernel", err) ||
        !(first = required(p, "ptr:sample_first", err)) ||
        !(samples = required(p, "ptr:samples", err)) || !(depth = required(p, "ptr:max_depth", err)) ||
        !(space = required(p, "ptr:colorspace", err)) ||
        !(p->sampler = required(p, "ptr:sampler", err)) ||
        !(p->direct_lighting = required(p, "ptr:direct_lighting", err)) ||
        !(p->noise_threshold = required(p, "ptr:noise_threshold", err)))
        return PTR_ERR_USAGE;
    if (strcmp(space, "lin_rec709"))
        return ptr_error_set(err, PTR_ERR_USAGE,
                             "%s: holds display-referred values (%s); merge needs scene-linear "
                             "parts (.exr without --bake-view)", p->path, space);
    p->first = atol(first);
    p->samples = atol(samples);
    p->max_depth = atol(depth);
    if (p->samples <= 0 || p->first < 0)
        return ptr_error_set(err, PTR_ERR_USAGE, "%s: no samples", p->path);
    return PTR_OK;
}

/* The value all parts give name, or "mixed"; "" if a part has none (parts
 * written before ptr recorded it). */
static void common_attr(const Part *parts, int count, const char *name, char *out, size_t size)
{
    const char *first = ptr_image_attr(parts[0].image, name);
    for (int i = 0; first && i < count; i++) {
        const char *value = ptr_image_attr(parts[i].image, name);
        if (!value)
            first = NULL;
        else if (strcmp(value, first))
            first = "mixed";
    }
    snprintf(out, size, "%s", first ? first : "");
}

static int has_passes(const Part *p)
{
    return ptr_image_albedo(p->image) && ptr_image_normal(p->image);
}

/* A part's colour as rendered: a denoised image's noisy layer, so that
 * nothing denoised is ever merged or denoised again. */
static const float *beauty(const Part *p)
{
    const float *noisy = ptr_image_noisy(p->image);
    return noisy ? noisy : ptr_image_pixels(p->image);
}

/* With --denoise: every part holds the passes the network needs. */
static PtrResult check_denoisable(const Part *parts, int count, PtrError *err)
{
    for (int i = 0; i < count; i++) {
        const int albedo = ptr_image_albedo(parts[i].image) != NULL,
                  normal = ptr_image_normal(parts[i].image) != NULL;
        if (!albedo || !normal)
            return ptr_error_set(err, PTR_ERR_USAGE,
                                 "%s: no %s layers to denoise with: render it with --passes "
                                 "albedo,normal or --denoise",
                                 parts[i].path,
                                 !albedo && !normal ? "albedo.R/G/B and normal.X/Y/Z"
                                 : !albedo          ? "albedo.R/G/B"
                                                    : "normal.X/Y/Z");
    }
    return PTR_OK;
}

static int overlap(const PtrImageLayout *a, const PtrImageLayout *b)
{
    return a->x < b->x + b->width && b->x < a->x + a->width && a->y < b->y + b->height &&
           b->y < a->y + a->height;
}

/* Parts of builds that fingerprint scenes two ways cannot be told parts of
 * one scene: the older ones are to be rendered again, the first named. */
static PtrResult check_fingerprints(const Part *parts, int count, PtrError *err)
{
    const Part *older = NULL, *newer = NULL;
    int older_count = 0;
    for (int i = 0; i < count; i++) {
        const Part *p = &parts[i];
        older_count += p->legacy_hash;
        if (p->legacy_hash && !older)
            older = p;
        if (!p->legacy_hash && !newer)
            newer = p;
    }
    if (!older || !newer)
        return PTR_OK;
    return ptr_error_set(err, PTR_ERR_USAGE,
                         "%s: written by an older ptr than %s (its scene fingerprinted as "
                         "ptr:scene_hash, not ptr:scene_xxh3); parts so written: %d of %d: "
                         "render those again to merge them",
                         older->path, newer->path, older_count, count);
}

/* Parts must come from one render, and never hold the same sample of the
 * same pixel twice. */
static PtrResult check_parts(const Part *parts, int count, PtrError *err)
{
    PtrResult res = check_fingerprints(parts, count, err);
    if (res != PTR_OK)
        return res;
    const Part *a = &parts[0];
    for (int i = 1; i < count; i++) {
        const Part *b = &parts[i];
        const char *what = strcmp(a->hash, b->hash)    ? "scene"
                           : strcmp(a->seed, b->seed) ? "seed"
                           : a->max_depth != b->max_depth ? "depth limit"
                           : strcmp(a->sampler, b->sampler) || strcmp(a->direct_lighting, b->direct_lighting) ||
                                   strcmp(a->noise_threshold, b->noise_threshold)
                               ? "estimator (sampler, direct lighting, noise threshold)"
                           : a->layout.full_width != b->layout.full_width ||
                                   a->layout.full_height != b->layout.full_height
                               ? "image size"
                               : NULL;
        if (!what && !ptr_image_alpha(a->image) != !ptr_image_alpha(b->image))
            what = "background (--transparent or not)";
        if (!what && !has_passes(a) != !has_passes(b))
            what = "set of passes (--passes or not)";
        if (what)
            return ptr_error_set(err, PTR_ERR_USAGE, "%s: another %s than %s: not parts of one render",
                                 b->path, what, a->path);
    }
    for (int i = 0; i < count; i++)
        for (int j = i + 1; j < count; j++) {
            const Part *p = &parts[i], *q = &parts[j];
            /* An adaptive pixel's samples are not a plain count: parts of an
             * adaptive render may only tile the image. */
            if (overlap(&p->layout, &q->layout) && strcmp(p->noise_threshold, "0"))
                return ptr_error_set(err, PTR_ERR_USAGE,
                                     "%s and %s: adaptive parts (--noise-threshold) must not "
                                     "overlap: split adaptive renders by --region only",
                                     p->path, q->path);
            if (overlap(&p->layout, &q->layout) && p->first < q->first + q->samples &&
                q->first < p->first + p->samples)
                return ptr_error_set(err, PTR_ERR_USAGE,
                                     "%s and %s: overlapping pixels hold the same samples (%ld..%ld "
                                     "and %ld..%ld)", p->path, q->path, p->first,
                                     p->first + p->samples - 1, q->first, q->first + q->samples - 1);
        }
    return PTR_OK;
}

static PtrResult combine(const Part *parts, int count, const char *output, const PtrOptions *o,
                         const PtrColor *color, PtrJobReport *report, PtrError *err)
{
    const int w = parts[0].layout.full_width, h = parts[0].layout.full_height;
    size_t pixels = (size_t)w * (size_t)h;
    /* Premultiplied colour, alpha and the passes alike are means over
     * samples: a pixel's sums hold colour, alpha, albedo and normal. */
    enum { ALPHA = 3, ALBEDO = 4, NORMAL = 7, SUMS = 10 };
    const int transparent = ptr_image_alpha(parts[0].image) != NULL, passes = has_passes(&parts[0]);
    double *sum = calloc(pixels * SUMS, sizeof *sum);
    long *n = calloc(pixels, sizeof *n);
    float *rgb = malloc(pixels * 3 * sizeof *rgb);
    float *alpha = transparent ? malloc(pixels * sizeof *alpha) : NULL;
    float *albedo = passes ? malloc(pixels * 3 * sizeof *albedo) : NULL;
    float *normal = passes ? malloc(pixels * 3 * sizeof *normal) : NULL;
    PtrResult res = PTR_OK;
    if (!sum || !n || !rgb || (transparent && !alpha) || (passes && (!albedo || !normal))) {
        res = ptr_error_set(err, PTR_ERR_NOMEM, "%s: out of memory", output);
        goto done;
    }
    long first = parts[0].first;
    for (int i = 0; i < count; i++) {
        const Part *p = &parts[i];
        const float *px = beauty(p), *pa = ptr_image_alpha(p->image);
        const float *pal = ptr_image_albedo(p->image), *pn = ptr_image_normal(p->image);
        first = p->first < first ? p->first : first;
        for (int y = 0; y < p->layout.height; y++)
            for (int x = 0; x < p->layout.width; x++) {
                int fx = p->layout.x + x, fy = p->layout.y + y;
                if (fx < 0 || fy < 0 || fx >= w || fy >= h)
                    continue;
                size_t at = (size_t)fy * (size_t)w + (size_t)fx;
                size_t from = (size_t)y * p->layout.width + x;
                double *s = &sum[SUMS * at];
                for (int c = 0; c < 3; c++) {
                    s[c] += (double)px[3 * from + c] * p->samples;
                    if (passes) {
                        s[ALBEDO + c] += (double)pal[3 * from + c] * p->samples;
                        s[NORMAL + c] += (double)pn[3 * from + c] * p->samples;
                    }
                }
                if (transparent)
                    s[ALPHA] += (double)pa[from] * p->samples;
                n[at] += p->samples;
            }
    }
    long fewest = n[0], most = n[0];
    for (size_t at = 0; at < pixels; at++) {
        if (n[at] == 0) {
            res = ptr_error_set(err, PTR_ERR_USAGE, "%s: no part covers pixel (%zu, %zu)", output,
                                at % (size_t)w, at / (size_t)w);
            goto done;
        }
        fewest = n[at] < fewest ? n[at] : fewest;
        most = n[at] > most ? n[at] : most;
        const double *s = &sum[SUMS * at];
        for (int c = 0; c < 3; c++) {
            rgb[3 * at + c] = (float)(s[c] / (double)n[at]);
            if (passes) {
                albedo[3 * at + c] = (float)(s[ALBEDO + c] / (double)n[at]);
                normal[3 * at + c] = (float)(s[NORMAL + c] / (double)n[at]);
            }
        }
        if (alpha)
            alpha[at] = (float)(s[ALPHA] / (double)n[at]);
    }
    if (fewest != most)
        fprintf(stderr, "ptr: warning: %s: pixels hold %ld to %ld samples\n", output, fewest, most);

    common_attr(parts, count, "ptr:kernel", report->kernel, sizeof report->kernel);
    common_attr(parts, count, "ptr:accel", report->accel, sizeof report->accel);
    char spheres[24];
    common_attr(parts, count, "ptr:spheres", spheres, sizeof spheres);
    report->spheres = strtoull(spheres, NULL, 10);
    report->width = w;
    report->height = h;
    report->sample_first = (uint32_t)first;
    report->samples = report->samples_requested = (uint32_t)fewest;
    report->seed = strtoull(parts[0].seed, NULL, 10);
    report->threads = ptr_thread_count(o->threads); /* the denoiser's, if it runs */
    const PtrImageLayout full = { w, h, 0, 0, w, h };
    PtrOutputInfo info = {
        .scene_path = parts[0].scene, .scene_hash = strtoull(parts[0].hash, NULL, 16),
        .legacy_scene_hash = parts[0].legacy_hash,
        .kernel = report->kernel, .accel = report->accel, .spheres = report->spheres,
        .sample_first = (uint32_t)first, .samples = (uint32_t)fewest,
        .seed = report->seed, .max_depth = (int)parts[0].max_depth,
        .sampler = parts[0].sampler, .direct_lighting = !strcmp(parts[0].direct_lighting, "on"),
        .noise_threshold = strtof(parts[0].noise_threshold, NULL),
        .min_samples = ptr_image_attr(parts[0].image, "ptr:min_samples")
                           ? (uint32_t)atol(ptr_image_attr(parts[0].image, "ptr:min_samples"))
                           : 0,
        .alpha = alpha, .albedo = albedo, .normal = normal,
        .output = ptr_options_output(o, color),
        .denoiser = o->denoiser, .denoise_quality = o->denoise, .threads = o->threads,
    };
    res = ptr_output_write(o->images, output, &full, rgb, &info, err);
done:
    free(sum);
    free(n);
    free(rgb);
    free(alpha);
    free(albedo);
    free(normal);
    return res;
}

PtrResult ptr_merge(char **paths, int count, const char *output, const PtrOptions *o,
                    const PtrColor *color, PtrJobReport *report)
{
    /* The report outlives the parts' metadata: it names the first part. */
    *report = (PtrJobReport){ .scene = count > 0 ? paths[0] : "merge", .output = output };
    PtrError err = { 0 };
    Part *parts = calloc((size_t)count, sizeof *parts);
    PtrResult res = parts ? PTR_OK : ptr_error_set(&err, PTR_ERR_NOMEM, "out of memory");
    for (int i = 0; res == PTR_OK && i < count; i++) {
        parts[i].path = paths[i];
        res = read_part(o->images, &parts[i], &err);
    }
    if (res == PTR_OK && o->denoise)
        res = check_denoisable(parts, count, &err);
    /* The passes a denoiser takes go where a --denoise render's go: into an
     * EXR, and nowhere in other formats. */
    if (res == PTR_OK)
        res = ptr_output_check(o->images, output, o->depth,
                               ptr_image_alpha(parts[0].image) != NULL,
                               has_passes(&parts[0]) && !o->denoise, &err);
    if (res == PTR_OK)
        res = check_parts(parts, count, &err);
    if (res == PTR_OK)
        res = combine(parts, count, output, o, color, report, &err);
    for (int i = 0; parts && i < count; i++)
        ptr_image_free(parts[i].image);
    free(parts);
    report->result = res;
    if (res != PTR_OK)
        snprintf(report->error, sizeof report->error, "%s", err.message);
    else if (!o->quiet && o->denoise_command)
        fprintf(stderr, "ptr: %s: denoised %s (%s), %dx%d, %" PRIu32 " spp\n", output, paths[0],
                o->denoise, report->width, report->height, report->samples);
    else if (!o->quiet)
        fprintf(stderr, "ptr: %s: merged %d parts%s%s, %dx%d, %" PRIu32 " spp\n", output, count,
                o->denoise ? ", denoised: " : "", o->denoise ? o->denoise : "", report->width,
                report->height, report->samples);
    return res;
}
