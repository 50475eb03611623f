#include "core/render.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <time.h>

#include "accel/cpu.h"
#include "core/threads.h"
#include "accel/huge.h"
#include "core/camera.h"
#include "core/lights.h"
#include "core/material.h"
#include "sampling/sampler.h"

enum { TILE_SIZE = 16 };

/* How far a new ray's origin is pushed off the surface, relative to the
 * magnitude of the numbers that locate it (|centre| + radius): the point is
 * re-projected onto the sphere, which leaves a few ulps of that magnitude of
 * error, and the kernel's f.f - r^2 adds a few more. Measured by
 * tests/stability/test_precision.c over 2 million hit points per level
 * (radii 1e-4 to 1e6, centres up to 1e7 away, down to grazing): 2^-23 lets
 * outward rays hit their own sphere again, 2^-22 stops grazing inward rays
 * short of the far side, 2^-21 and above never fail. Smaller is better (the
 * offset shifts contact shadows), so the smallest safe power of two. */
#define SPAWN_OFFSET_SCALE 0x1.0p-21f

PtrRay ptr_spawn_ray(PtrVec3 centre, float radius, PtrVec3 outward_normal, PtrVec3 dir)
{
    float offset = SPAWN_OFFSET_SCALE * (v3_max_abs(centre) + radius);
    if (v3_dot(dir, outward_normal) < 0.0f)
        offset = -offset;
    PtrVec3 o = v3_add(centre, v3_scale(outward_normal, radius + offset));
    return (PtrRay){ { o.x, o.y, o.z }, 0.0f, { dir.x, dir.y, dir.z }, INFINITY };
}

PtrVec3 ptr_hit_normal(const PtrSpheres *spheres, const PtrRay *ray, const PtrHit *hit)
{
    PtrVec3 p = v3_madd(v3(ray->org[0], ray->org[1], ray->org[2]),
                        v3(ray->dir[0], ray->dir[1], ray->dir[2]), hit->t);
    return v3_normalize(v3_sub(p, ptr_sphere_centre(spheres, hit->sphere)));
}

typedef struct PathContext {
    const PtrScene *scene;
    const PtrAccel *accel;
    const PtrRenderSettings *settings;
    const PtrLights *lights;
    uint64_t *rays;
} PathContext;

/* A diffuse vertex where an emitter was sampled: what the next vertex needs
 * to weigh the emission the scattered ray finds against that sample. */
typedef struct LitVertex {
    int sampled;       /* 0: the emission found next counts fully */
    PtrVec3 point;
    uint32_t sphere;   /* the sphere it lies on */
    int side;          /* 1 on its outside, -1 on its inside */
    float scatter_pdf; /* of the direction taken */
} LitVertex;

/* Where ray met the sphere hit names: the point on its surface and the
 * outward normal there (for the stability suite's fixed t_min, the point
 * along the ray, as the seed renderer took it). */
static void surface_at(const PathContext *ctx, const PtrRay *ray, const PtrHit *hit,
                       PtrVec3 *point, PtrVec3 *normal)
{
    const PtrScene *scene = ctx->scene;
    const PtrSpheres *spheres = &scene->spheres;
    if (ptr_is_huge(scene, hit->sphere) && ctx->settings->fixed_tmin == 0.0f) {
        ptr_huge_surface(scene, ray, hit, point, normal);
        return;
    }
    *normal = ptr_hit_normal(spheres, ray, hit);
    *point = ctx->settings->fixed_tmin > 0.0f
                 ? v3_madd(v3(ray->org[0], ray->org[1], ray->org[2]),
                           v3(ray->dir[0], ray->dir[1], ray->dir[2]), hit->t)
                 : v3_madd(ptr_sphere_centre(spheres, hit->sphere), *normal,
                           spheres->radius[hit->sphere]);
}

/* A ray leaving the surface of sphere at point (outward normal there) along
 * dir, by the settings' method. */
static PtrRay leave_surface(const PathContext *ctx, uint32_t sphere, PtrVec3 point,
                            PtrVec3 outward_normal, PtrVec3 dir)
{
    const PtrSpheres *spheres = &ctx->scene->spheres;
    float tmin = ctx->settings->fixed_tmin;
    if (tmin > 0.0f)
        return (PtrRay){ { point.x, point.y, point.z }, tmin, { dir.x, dir.y, dir.z }, INFINITY };
    if (ptr_is_huge(ctx->scene, sphere))
        return ptr_huge_spawn_ray(ctx->scene, sphere, point, dir);
    return ptr_spawn_ray(ptr_sphere_centre(spheres, sphere), spheres->radius[sphere],
                         outward_normal, dir);
}

/* Whether a shadow ray reaches the emitter: the one closest-hit query of a
 * shadow ray, through the intersector camera rays use. Its tmax lies just
 * beyond the point sampled on the emitter, so a miss or a hit on the emitter
 * itself means nothing stands in between. */
static int reaches_emitter(const PathContext *ctx, const PtrRay *ray, uint32_t emitter)
{
    PtrHit hit;
    ++*ctx->rays;
    return !ptr_trace(ctx->accel, ray, &hit) || hit.sphere == emitter;
}

/* Power heuristic (Veach), written so that an infinite density on either
 * side gives 0 or 1 rather than NaN. */
static float power_heuristic(float pdf, float other_pdf)
{
    float ratio = other_pdf / pdf;
    return 1.0f / (1.0f + ratio * ratio);
}

static PtrLightView view_from(const LitVertex *v, const PtrSpheres *spheres, uint32_t emitter)
{
    return ptr_light_view(v->point, ptr_sphere_centre(spheres, emitter), spheres->radius[emitter],
                          v->sphere == emitter ? v->side : 0);
}

/* Light sampling at a diffuse vertex: one emitter picked by power, one
 * direction towards it, one shadow ray, weighed against scattering. */
static PtrVec3 sample_emitter(const PathContext *ctx, const PtrSampler *sampler, int bounce,
                              const PtrMaterial *m, const LitVertex *at, PtrVec3 n,
                              PtrVec3 outward_normal)
{
    const PtrScene *scene = ctx->scene;
    const PtrSpheres *spheres = &scene->spheres;
    uint32_t pick[2];
    float u[2];
    ptr_sampler_2d_bits(sampler, ptr_bounce_dim(bounce, PTR_SLOT_LIGHT_PICK), pick);
    ptr_sampler_2d(sampler, ptr_bounce_dim(bounce, PTR_SLOT_LIGHT_POINT), u);
    uint32_t emitter = ctx->lights->sphere[ptr_lights_pick(ctx->lights, pick)];
    PtrVec3 dir;
    float distance, pdf;
    if (!ptr_light_sample(view_from(at, spheres, emitter), at->point,
                          ptr_sphere_centre(spheres, emitter), spheres->radius[emitter], u, &dir,
                          &distance, &pdf))
        return v3_splat(0.0f);
    pdf *= ptr_lights_pick_pdf(ctx->lights, scene, emitter);
    float scatter_pdf = ptr_diffuse_pdf(n, dir);
    if (!(scatter_pdf > 0.0f) || !(pdf > 0.0f))
        return v3_splat(0.0f);
    PtrRay shadow = leave_surface(ctx, at->sphere, at->point, outward_normal, dir);
    shadow.tmax = ptr_maxf(distance * 1.001f, 2.0f * shadow.tmin);
    if (!reaches_emitter(ctx, &shadow, emitter))
        return v3_splat(0.0f);
    PtrVec3 emission = scene->materials[spheres->material[emitter]].emission;
    float weight = power_heuristic(pdf, scatter_pdf) / pdf;
    return v3_scale(v3_mul(ptr_diffuse_eval(m, n, dir), emission), weight);
}

/* The weight of emission a scattered ray found on emitter (at distance t
 * along dir, outward normal there) after light sampling at vertex from. */
static float scattered_emission_weight(const PathContext *ctx, const LitVertex *from,
                                       uint32_t emitter, PtrVec3 dir, float t, PtrVec3 normal)
{
    const PtrSpheres *spheres = &ctx->scene->spheres;
    float light_pdf = ptr_light_pdf(view_from(from, spheres, emitter), from->point,
                                    ptr_sphere_centre(spheres, emitter), spheres->radius[emitter],
                                    dir, t, normal);
    if (!(light_pdf > 0.0f))
        return 1.0f;
    light_pdf *= ptr_lights_pick_pdf(ctx->lights, ctx->scene, emitter);
    return power_heuristic(from->scatter_pdf, light_pdf);
}

/* The radiance one camera ray carries back. A path has at most max_depth
 * rays from the camera or a scattering; shadow rays do not count, since they
 * estimate what the next ray would find and so only where it may exist. */
static PtrVec3 trace_path(const PathContext *ctx, const PtrSampler *sampler, PtrRay ray)
{
    const PtrScene *scene = ctx->scene;
    const PtrRenderSettings *settings = ctx->settings;
    const PtrSpheres *spheres = &scene->spheres;
    int sample_lights = settings->direct_lighting == PTR_ON && ctx->lights->count > 0;
    PtrVec3 radiance = v3_splat(0.0f);
    PtrVec3 throughput = v3_splat(1.0f);
    LitVertex lit = { 0 };

    for (int depth = 0; depth < settings->max_depth; depth++) {
        PtrHit hit;
        PtrVec3 dir = v3(ray.dir[0], ray.dir[1], ray.dir[2]);
        ++*ctx->rays;
        if (!ptr_trace(ctx->accel, &ray, &hit)) {
            radiance = v3_add(radiance, v3_mul(throughput, ptr_sky_radiance(&scene->sky, dir)));
            break;
        }
        const PtrMaterial *m = &scene->materials[spheres->material[hit.sphere]];
        PtrMaterial tinted;
        if (spheres->color) {
            tinted = *m;
            tinted.albedo = v3_mul(m->albedo, ptr_sphere_color(spheres, hit.sphere));
            m = &tinted;
        }
        PtrVec3 normal, point;
        surface_at(ctx, &ray, &hit, &point, &normal);
        if (v3_max_comp(m->emission) > 0.0f) {
            float weight = lit.sampled ? scattered_emission_weight(ctx, &lit, hit.sphere, dir,
                                                                   v3_length(v3_sub(point, lit.point)),
                                                                   normal)
                                       : 1.0f;
            radiance = v3_add(radiance, v3_scale(v3_mul(throughput, m->emission), weight));
        }

        int entering = v3_dot(dir, normal) < 0.0f;
        lit = (LitVertex){ .sampled = sample_lights && m->kind == PTR_MATERIAL_DIFFUSE &&
                                      depth + 1 < settings->max_depth,
                           .point = point, .sphere = hit.sphere, .side = entering ? 1 : -1 };
        PtrVec3 n = entering ? normal : v3_neg(normal);
        if (lit.sampled)
            radiance = v3_add(radiance, v3_mul(throughput, sample_emitter(ctx, sampler, depth, m,
                                                                          &lit, n, normal)));

        float u[4]; /* u[3] is unused: one pair holds the third number */
        ptr_sampler_2d(sampler, ptr_bounce_dim(depth, PTR_SLOT_BSDF), u);
        ptr_sampler_2d(sampler, ptr_bounce_dim(depth, PTR_SLOT_BSDF_EXTRA), u + 2);
        PtrVec3 out_dir, attenuation;
        if (!ptr_scatter(m, dir, normal, u, &out_dir, &attenuation))
            break;
        if (lit.sampled)
            lit.scatter_pdf = ptr_diffuse_pdf(n, out_dir);
        throughput = v3_mul(throughput, attenuation);
        if (v3_max_comp(throughput) <= 0.0f)
            break;
        ray = leave_surface(ctx, hit.sphere, point, normal, out_dir);
    }
    return radiance;
}

typedef struct RenderJob {
    const PtrScene *scene;
    const PtrAccel *accel;
    const PtrRenderSettings *settings;
    PtrView view;
    PtrRegion region;
    PtrLights lights;
    uint32_t first, count;
    double *sums;
    int tiles_x, tile_count;
    atomic_int next_tile, tiles_done;
    pthread_mutex_t lock; /* guards workers_running, signalled on all_done */
    pthread_cond_t all_done;
    int workers_running;
} RenderJob;

typedef struct Worker {
    RenderJob *job;
    PtrThread *thread;
    uint64_t rays;
} Worker;

/* Adaptive sampling's estimate of a pixel's remaining error, in the manner
 * of Cycles: the mean of all its samples against the mean of its odd ones,
 * summed over channels, relative to the square root of the brightness (the
 * eye forgives noise in bright pixels in about that proportion). */
static double pixel_error(const double *acc)
{
    double n = acc[PTR_ACCUM_COUNT], half = floor(n / 2), difference = 0, brightness = 0;
    for (int c = 0; c < 3; c++) {
        double all = acc[PTR_ACCUM_SUM + c] / n;
        difference += fabs(all - acc[PTR_ACCUM_ODD + c] / half);
        brightness += all;
    }
    return difference / (1e-4 + sqrt(brightness));
}

/* Adaptive sampling looks at a pixel only after sample counts that are
 * multiples of this (from the minimum on): the decision depends on the
 * pixel's own samples alone, never on passes or threads, and Sobol' points
 * are complete nets at these counts. */
enum { ADAPTIVE_STEP = 16 };

static void render_pixel(const RenderJob *job, int x, int y, uint64_t *rays)
{
    const PtrRenderSettings *s = job->settings;
    /* Streams are keyed by full-image pixel, so a region renders the very
     * samples the whole image would. */
    uint64_t pixel = (uint64_t)y * (uint64_t)s->width + (uint64_t)x;
    double *acc = job->sums + PTR_ACCUM_STRIDE * ((size_t)(y - job->region.y0) *
                                                  (size_t)(job->region.x1 - job->region.x0) +
                                                  (size_t)(x - job->region.x0));
    PathContext ctx = { job->scene, job->accel, s, &job->lights, rays };
    for (uint32_t i = job->first; i < job->first + job->count && !acc[PTR_ACCUM_STOPPED]; i++) {
        PtrSampler sampler = ptr_sampler_for_sample(s->sampler, s->seed, pixel, i);
        float pixel_u[2], lens_u[2];
        ptr_sampler_2d(&sampler, PTR_DIM_PIXEL, pixel_u);
        ptr_sampler_2d(&sampler, PTR_DIM_LENS, lens_u);
        float lens_r = sqrtf(lens_u[0]), lens_phi = 2.0f * PTR_PI * lens_u[1];
        PtrVec3 o, d;
        ptr_view_ray(&job->view, x, y, pixel_u[0], pixel_u[1], lens_r * cosf(lens_phi),
                     lens_r * sinf(lens_phi), &o, &d);
        PtrRay ray = { { o.x, o.y, o.z }, 0.0f, { d.x, d.y, d.z }, INFINITY };
        PtrVec3 l = trace_path(&ctx, &sampler, ray);
        acc[PTR_ACCUM_SUM + 0] += l.x;
        acc[PTR_ACCUM_SUM + 1] += l.y;
        acc[PTR_ACCUM_SUM + 2] += l.z;
        if (i & 1) {
            acc[PTR_ACCUM_ODD + 0] += l.x;
            acc[PTR_ACCUM_ODD + 1] += l.y;
            acc[PTR_ACCUM_ODD + 2] += l.z;
        }
        acc[PTR_ACCUM_COUNT] += 1;
        uint32_t taken = i + 1;
        if (s->noise_threshold > 0 && taken >= s->min_samples && taken % ADAPTIVE_STEP == 0 &&
            pixel_error(acc) < s->noise_threshold)
            acc[PTR_ACCUM_STOPPED] = 1;
    }
}

void ptr_accum_resolve(const double *acc, size_t pixels, float *rgb, float *sample_counts)
{
    for (size_t p = 0; p < pixels; p++, acc += PTR_ACCUM_STRIDE) {
        double n = acc[PTR_ACCUM_COUNT];
        for (int c = 0; c < 3; c++)
            rgb[3 * p + c] = n > 0 ? (float)(acc[PTR_ACCUM_SUM + c] / n) : 0.0f;
        if (sample_counts)
            sample_counts[p] = (float)n;
    }
}

static void *render_worker(void *arg)
{
    Worker *w = arg;
    RenderJob *job = w->job;
    const PtrRegion *r = &job->region;
    for (;;) {
        int tile = atomic_fetch_add(&job->next_tile, 1);
        if (tile >= job->tile_count)
            break;
        int x0 = r->x0 + (tile % job->tiles_x) * TILE_SIZE;
        int y0 = r->y0 + (tile / job->tiles_x) * TILE_SIZE;
        int x1 = x0 + TILE_SIZE < r->x1 ? x0 + TILE_SIZE : r->x1;
        int y1 = y0 + TILE_SIZE < r->y1 ? y0 + TILE_SIZE : r->y1;
        for (int y = y0; y < y1; y++)
            for (int x = x0; x < x1; x++)
                render_pixel(job, x, y, &w->rays);
        atomic_fetch_add(&job->tiles_done, 1);
    }
    pthread_mutex_lock(&job->lock);
    if (--job->workers_running == 0)
        pthread_cond_signal(&job->all_done);
    pthread_mutex_unlock(&job->lock);
    return NULL;
}

PtrRegion ptr_render_region(const PtrRenderSettings *s)
{
    PtrRegion r = s->region;
    if (!r.x0 && !r.y0 && !r.x1 && !r.y1)
        r = (PtrRegion){ 0, 0, s->width, s->height };
    if (r.x0 < 0 || r.y0 < 0 || r.x1 > s->width || r.y1 > s->height || r.x0 >= r.x1 ||
        r.y0 >= r.y1)
        return (PtrRegion){ 0, 0, 0, 0 };
    return r;
}

PtrResult ptr_render_samples(const PtrScene *scene, const PtrAccel *accel,
                             const PtrRenderSettings *settings, uint32_t first, uint32_t count,
                             double *sums, PtrTickFn tick, void *user, PtrRenderStats *stats,
                             PtrError *err)
{
    RenderJob job = {
        .scene = scene, .accel = accel, .settings = settings, .first = first, .count = count,
        .sums = sums, .region = ptr_render_region(settings),
    };
    if (settings->max_depth < 0 || !(settings->fixed_tmin >= 0.0f) || first + count < first)
        return ptr_error_set(err, PTR_ERR_USAGE,
                             "max depth and fixed t_min must not be negative, samples must fit 32 bits");
    if (job.region.x1 == 0)
        return ptr_error_set(err, PTR_ERR_USAGE, "the region lies outside the %dx%d image",
                             settings->width, settings->height);
    if (!ptr_view_init(&job.view, &scene->camera, settings->width, settings->height))
        return ptr_error_set(err, PTR_ERR_SCENE_INVALID,
                             "camera is degenerate (look-from equals look-at, up along the view, "
                             "field of view outside (0, 180) degrees, or bad focus distance/aperture)");
    PtrResult lights_res = ptr_lights_init(&job.lights, scene, err);
    if (lights_res != PTR_OK)
        return lights_res;
    job.tiles_x = (job.region.x1 - job.region.x0 + TILE_SIZE - 1) / TILE_SIZE;
    int tiles_y = (job.region.y1 - job.region.y0 + TILE_SIZE - 1) / TILE_SIZE;
    job.tile_count = job.tiles_x * tiles_y;
    atomic_init(&job.next_tile, 0);
    atomic_init(&job.tiles_done, 0);

    int threads = settings->threads > 0 ? settings->threads : ptr_online_cpus();
    if (threads > job.tile_count)
        threads = job.tile_count;
    Worker *workers = calloc((size_t)threads, sizeof *workers);
    if (!workers) {
        ptr_lights_free(&job.lights);
        return ptr_error_set(err, PTR_ERR_NOMEM, "cannot allocate %d render threads", threads);
    }

    double start = ptr_now_seconds();
    int started = 0;
    pthread_mutex_init(&job.lock, NULL);
    pthread_cond_init(&job.all_done, NULL);
    job.workers_running = threads;
    for (; started < threads; started++) {
        workers[started].job = &job;
        if (!(workers[started].thread = ptr_thread_start(render_worker, &workers[started])))
            break;
    }
    pthread_mutex_lock(&job.lock);
    job.workers_running -= threads - started;
    pthread_mutex_unlock(&job.lock);
    if (started == 0) {
        /* No thread could be created: render here. */
        job.workers_running = 1;
        render_worker(&workers[0]);
    }
    /* This thread watches: it reports progress until the last worker says
     * it is done. */
    pthread_mutex_lock(&job.lock);
    while (job.workers_running > 0) {
        if (!tick) {
            pthread_cond_wait(&job.all_done, &job.lock);
            continue;
        }
        pthread_mutex_unlock(&job.lock);
        tick(user, (double)atomic_load(&job.tiles_done) / job.tile_count);
        pthread_mutex_lock(&job.lock);
        struct timespec until;
        clock_gettime(CLOCK_REALTIME, &until);
        until.tv_nsec += 100 * 1000 * 1000;
        if (until.tv_nsec >= 1000000000) {
            until.tv_sec++;
            until.tv_nsec -= 1000000000;
        }
        if (job.workers_running > 0)
            pthread_cond_timedwait(&job.all_done, &job.lock, &until);
    }
    pthread_mutex_unlock(&job.lock);
    uint64_t rays = started == 0 ? workers[0].rays : 0;
    for (int i = 0; i < started; i++) {
        ptr_thread_join(workers[i].thread);
        rays += workers[i].rays;
    }
    double seconds = ptr_now_seconds() - start;
    free(workers);
    ptr_lights_free(&job.lights);
    pthread_cond_destroy(&job.all_done);
    pthread_mutex_destroy(&job.lock);
    if (tick)
        tick(user, 1.0);
    if (stats)
        *stats = (PtrRenderStats){ .seconds = seconds, .rays = rays,
                                   .threads = started ? started : 1 };
    return PTR_OK;
}

PtrResult ptr_render(const PtrScene *scene, const PtrAccel *accel,
                     const PtrRenderSettings *settings, float *rgb,
                     PtrRenderStats *stats, PtrError *err)
{
    if (settings->samples == 0)
        return ptr_error_set(err, PTR_ERR_USAGE, "samples must be positive");
    PtrRegion r = ptr_render_region(settings);
    size_t pixels = (size_t)(r.x1 - r.x0) * (size_t)(r.y1 - r.y0);
    double *acc = calloc(pixels ? pixels * PTR_ACCUM_STRIDE : 1, sizeof *acc);
    if (!acc)
        return ptr_error_set(err, PTR_ERR_NOMEM, "cannot allocate a %dx%d image",
                             r.x1 - r.x0, r.y1 - r.y0);
    PtrResult res = ptr_render_samples(scene, accel, settings, 0, settings->samples, acc, NULL,
                                       NULL, stats, err);
    if (res == PTR_OK)
        ptr_accum_resolve(acc, pixels, rgb, NULL);
    free(acc);
    return res;
}
