#include "core/render.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <time.h>

#include "accel/cpu.h"
#include "accel/huge.h"
#include "core/camera.h"
#include "core/material.h"

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

/* The radiance one camera ray carries back. */
static PtrVec3 trace_path(const PtrScene *scene, const PtrAccel *accel, PtrRay ray,
                          const PtrRenderSettings *settings, PtrRng *rng, uint64_t *rays)
{
    const PtrSpheres *spheres = &scene->spheres;
    PtrVec3 radiance = v3_splat(0.0f);
    PtrVec3 throughput = v3_splat(1.0f);

    for (int depth = 0; depth < settings->max_depth; depth++) {
        PtrHit hit;
        PtrVec3 dir = v3(ray.dir[0], ray.dir[1], ray.dir[2]);
        ++*rays;
        if (!ptr_trace(accel, &ray, &hit)) {
            radiance = v3_add(radiance, v3_mul(throughput, ptr_sky_radiance(&scene->sky, dir)));
            break;
        }
        const PtrMaterial *m = &scene->materials[spheres->material[hit.sphere]];
        radiance = v3_add(radiance, v3_mul(throughput, m->emission));

        const int huge = ptr_is_huge(scene, hit.sphere);
        PtrVec3 normal = huge ? ptr_huge_hit_normal(scene, &ray, &hit)
                              : ptr_hit_normal(spheres, &ray, &hit);

        PtrVec3 out_dir, attenuation;
        if (!ptr_scatter(m, dir, normal, rng, &out_dir, &attenuation))
            break;
        throughput = v3_mul(throughput, attenuation);
        if (v3_max_comp(throughput) <= 0.0f)
            break;
        if (settings->fixed_tmin > 0.0f) {
            PtrVec3 p = v3_madd(v3(ray.org[0], ray.org[1], ray.org[2]), dir, hit.t);
            ray = (PtrRay){ { p.x, p.y, p.z }, settings->fixed_tmin,
                            { out_dir.x, out_dir.y, out_dir.z }, INFINITY };
        } else if (huge) {
            ray = ptr_huge_spawn_ray(scene, &ray, &hit, out_dir);
        } else {
            ray = ptr_spawn_ray(ptr_sphere_centre(spheres, hit.sphere),
                                spheres->radius[hit.sphere], normal, out_dir);
        }
    }
    return radiance;
}

typedef struct RenderJob {
    const PtrScene *scene;
    const PtrAccel *accel;
    const PtrRenderSettings *settings;
    PtrView view;
    PtrRegion region;
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
    pthread_t thread;
    uint64_t rays;
} Worker;

static void render_pixel(const RenderJob *job, int x, int y, uint64_t *rays)
{
    const PtrRenderSettings *s = job->settings;
    /* Streams are keyed by full-image pixel, so a region renders the very
     * samples the whole image would. */
    uint64_t pixel = (uint64_t)y * (uint64_t)s->width + (uint64_t)x;
    double *sum = job->sums + 3 * ((size_t)(y - job->region.y0) *
                                   (size_t)(job->region.x1 - job->region.x0) +
                                   (size_t)(x - job->region.x0));
    for (uint32_t i = job->first; i < job->first + job->count; i++) {
        PtrRng rng = ptr_rng_for_sample(s->seed, pixel, i);
        float sx = ptr_rng_float(&rng), sy = ptr_rng_float(&rng);
        float lens_r = sqrtf(ptr_rng_float(&rng));
        float lens_phi = 2.0f * PTR_PI * ptr_rng_float(&rng);
        PtrVec3 o, d;
        ptr_view_ray(&job->view, x, y, sx, sy, lens_r * cosf(lens_phi),
                     lens_r * sinf(lens_phi), &o, &d);
        PtrRay ray = { { o.x, o.y, o.z }, 0.0f, { d.x, d.y, d.z }, INFINITY };
        PtrVec3 l = trace_path(job->scene, job->accel, ray, s, &rng, rays);
        sum[0] += l.x;
        sum[1] += l.y;
        sum[2] += l.z;
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
    job.tiles_x = (job.region.x1 - job.region.x0 + TILE_SIZE - 1) / TILE_SIZE;
    int tiles_y = (job.region.y1 - job.region.y0 + TILE_SIZE - 1) / TILE_SIZE;
    job.tile_count = job.tiles_x * tiles_y;
    atomic_init(&job.next_tile, 0);
    atomic_init(&job.tiles_done, 0);

    int threads = settings->threads > 0 ? settings->threads : ptr_online_cpus();
    if (threads > job.tile_count)
        threads = job.tile_count;
    Worker *workers = calloc((size_t)threads, sizeof *workers);
    if (!workers)
        return ptr_error_set(err, PTR_ERR_NOMEM, "cannot allocate %d render threads", threads);

    double start = ptr_now_seconds();
    int started = 0;
    pthread_mutex_init(&job.lock, NULL);
    pthread_cond_init(&job.all_done, NULL);
    job.workers_running = threads;
    for (; started < threads; started++) {
        workers[started].job = &job;
        if (pthread_create(&workers[started].thread, NULL, render_worker, &workers[started]))
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
        pthread_join(workers[i].thread, NULL);
        rays += workers[i].rays;
    }
    double seconds = ptr_now_seconds() - start;
    free(workers);
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
    size_t values = (size_t)(r.x1 - r.x0) * (size_t)(r.y1 - r.y0) * 3;
    double *sums = calloc(values ? values : 1, sizeof *sums);
    if (!sums)
        return ptr_error_set(err, PTR_ERR_NOMEM, "cannot allocate a %dx%d image",
                             r.x1 - r.x0, r.y1 - r.y0);
    PtrResult res = ptr_render_samples(scene, accel, settings, 0, settings->samples, sums, NULL,
                                       NULL, stats, err);
    for (size_t i = 0; res == PTR_OK && i < values; i++)
        rgb[i] = (float)(sums[i] / (double)settings->samples);
    free(sums);
    return res;
}
