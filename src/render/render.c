#include "render/render.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "base/cpu.h"
#include "base/threads.h"
#include "render/camera.h"
#include "render/path.h"
#include "sampling/sampler.h"

/* The radiance one camera ray carries back, one path at a time: the
 * reference the bundles (bundle.c) match bit for bit. A path has at most
 * max_depth rays from the camera or a scattering; shadow rays do not count,
 * since they estimate what the next ray would find and so only where it may
 * exist. *covered says whether the camera ray hit a sphere; *pass gets
 * the path's passes where the settings ask for them. */
static PtrVec3 trace_path(const PtrPathJob *job, const PtrSampler *sampler, PtrRay ray,
                          uint64_t *rays, int *covered, PtrPathPass *pass)
{
    const PtrScene *scene = job->scene;
    const PtrRenderSettings *settings = job->settings;
    const PtrSpheres *spheres = &scene->spheres;
    PtrVec3 radiance = v3_splat(0.0f);
    PtrVec3 throughput = v3_splat(1.0f);
    PtrLitVertex lit = { 0 };
    *covered = 0;

    for (int depth = 0; ptr_path_may_trace(settings, depth); depth++) {
        PtrHit hit;
        PtrVec3 dir = v3(ray.dir[0], ray.dir[1], ray.dir[2]);
        ++*rays;
        if (!ptr_trace(job->accel, &ray, &hit)) {
            PtrVec3 sky = ptr_sky_radiance(&scene->sky, dir);
            radiance = ptr_path_add_found(radiance, throughput, 0, sky, v3_splat(0.0f), 1.0f);
            if (settings->passes)
                ptr_path_pass_sky(pass, sky);
            break;
        }
        *covered = 1;
        PtrMaterial m = scene->materials[ptr_sphere_material(spheres, hit.sphere)];
        m.albedo = ptr_path_albedo(spheres, hit.sphere, m.albedo);
        PtrVec3 normal, point;
        ptr_path_surface(job, &ray, &hit, &point, &normal);
        float weight = ptr_path_weighs_emission(&lit, m.emission)
                           ? ptr_path_emission_weight(job, &lit, hit.sphere, dir, point, normal)
                           : 1.0f;
        radiance = ptr_path_add_found(radiance, throughput, 1, v3_splat(0.0f), m.emission, weight);

        lit = ptr_path_vertex(job, m.kind, depth, point, hit.sphere,
                              v3_dot(dir, normal) < 0.0f);
        PtrVec3 n = ptr_facing_normal(dir, normal);
        if (settings->passes)
            ptr_path_pass_surface(pass, m.kind, m.fuzz, m.albedo, n);
        if (lit.sampled)
            radiance = v3_add(radiance,
                              v3_mul(throughput, ptr_path_sample_emitter(job, sampler, depth, &m,
                                                                         &lit, n, normal, rays)));

        float u[4]; /* u[3] is unused: one pair holds the third number */
        ptr_sampler_2d(sampler, ptr_bounce_dim(depth, PTR_SLOT_BSDF), u);
        ptr_sampler_2d(sampler, ptr_bounce_dim(depth, PTR_SLOT_BSDF_EXTRA), u + 2);
        PtrVec3 out_dir, attenuation;
        int scattered = ptr_scatter(&m, dir, normal, u, &out_dir, &attenuation);
        if (lit.sampled)
            lit.scatter_pdf = ptr_material_pdf(&m, n, out_dir);
        throughput = v3_mul(throughput, attenuation);
        if (!ptr_path_goes_on(settings, depth, scattered, throughput))
            break;
        ray = ptr_path_leave(job, hit.sphere, point, normal, out_dir);
    }
    return radiance;
}

/* The job's samples of pixels [x0, x1) x [y0, y1), a path at a time. */
static PTR_DECL_RENDER_TILE(render_tile_by_path)
{
    const PtrRenderSettings *s = job->settings;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) {
            double *acc = ptr_path_pixel_sums(job, x, y);
            uint64_t key = ptr_path_pixel_key(job, x, y);
            for (uint32_t i = job->first; i < job->first + job->count && !acc[PTR_ACCUM_STOPPED];
                 i++) {
                PtrSampler sampler = { s->sampler, key, i };
                PtrVec3 o, d;
                ptr_path_camera_ray(job, key, i, x, y, &o, &d);
                PtrRay ray = { { o.x, o.y, o.z }, 0.0f, { d.x, d.y, d.z }, INFINITY };
                int covered;
                PtrPathPass pass = ptr_path_pass_start();
                PtrVec3 radiance = trace_path(job, &sampler, ray, rays, &covered, &pass);
                ptr_path_accumulate(s, acc, i, radiance, covered, &pass);
            }
        }
}

typedef struct RenderJob {
    PtrPathJob paths;
    PtrRenderTileFn render_tile;
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
    double finished; /* when it found no tile left */
} Worker;

static const char *const integrator_names[] = {
    [PTR_INTEGRATOR_AUTO] = "auto", [PTR_INTEGRATOR_PATHS] = "paths",
    [PTR_INTEGRATOR_BUNDLES] = "bundles",
};

const char *ptr_integrator_name(PtrIntegrator integrator)
{
    return integrator_names[integrator];
}

PtrResult ptr_integrator_parse(const char *text, PtrIntegrator *integrator, PtrError *err)
{
    for (int i = PTR_INTEGRATOR_AUTO; i <= PTR_INTEGRATOR_BUNDLES; i++)
        if (!strcmp(text, integrator_names[i])) {
            *integrator = (PtrIntegrator)i;
            return PTR_OK;
        }
    return ptr_error_set(err, PTR_ERR_USAGE, "'%s' is not auto, paths or bundles", text);
}

PtrIntegrator ptr_integrator_for_level(PtrCpuLevel level)
{
#if PTR_HAVE_BUNDLES
    if (level >= PTR_CPU_AVX2)
        return PTR_INTEGRATOR_BUNDLES;
#else
    (void)level;
#endif
    return PTR_INTEGRATOR_PATHS;
}

int ptr_integrator_available(PtrIntegrator integrator, PtrCpuLevel level)
{
    return integrator != PTR_INTEGRATOR_BUNDLES ||
           ptr_integrator_for_level(level) == PTR_INTEGRATOR_BUNDLES;
}

PtrIntegrator ptr_integrator_resolve(PtrIntegrator integrator, PtrCpuLevel level)
{
    return integrator == PTR_INTEGRATOR_AUTO ? ptr_integrator_for_level(level) : integrator;
}

PtrIntegrator ptr_render_integrator(const PtrRenderSettings *s)
{
    return s->fixed_tmin > 0.0f ? PTR_INTEGRATOR_PATHS
                                : ptr_integrator_resolve(s->integrator, ptr_cpu_level());
}

static PtrRenderTileFn render_tile_for(PtrIntegrator integrator)
{
#if PTR_HAVE_BUNDLES
    if (integrator == PTR_INTEGRATOR_BUNDLES)
        return ptr_render_tile_bundled_avx2;
#else
    (void)integrator;
#endif
    return render_tile_by_path;
}

static void *render_worker(void *arg)
{
    Worker *w = arg;
    RenderJob *job = w->job;
    const PtrRegion *r = &job->paths.region;
    /* Counted here, not in *w: the workers' counts share a cache line, and
     * writing it at every ray cost a third of the second thread's speed. */
    uint64_t rays = 0;
    for (;;) {
        int tile = atomic_fetch_add(&job->next_tile, 1);
        if (tile >= job->tile_count)
            break;
        int x0 = r->x0 + (tile % job->tiles_x) * PTR_TILE_SIZE;
        int y0 = r->y0 + (tile / job->tiles_x) * PTR_TILE_SIZE;
        int x1 = x0 + PTR_TILE_SIZE < r->x1 ? x0 + PTR_TILE_SIZE : r->x1;
        int y1 = y0 + PTR_TILE_SIZE < r->y1 ? y0 + PTR_TILE_SIZE : r->y1;
        job->render_tile(&job->paths, x0, y0, x1, y1, &rays);
        atomic_fetch_add(&job->tiles_done, 1);
    }
    w->rays = rays;
    w->finished = ptr_now_seconds();
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
    const PtrIntegrator integrator = ptr_render_integrator(settings);
    RenderJob job = {
        .paths = { .scene = scene, .accel = accel, .settings = settings, .first = first,
                   .count = count, .sums = sums, .region = ptr_render_region(settings) },
        .render_tile = render_tile_for(integrator),
    };
    if (settings->max_depth < 0 || !(settings->fixed_tmin >= 0.0f) || first + count < first)
        return ptr_error_set(err, PTR_ERR_USAGE,
                             "max depth and fixed t_min must not be negative, samples must fit 32 bits");
    if (!ptr_integrator_available(integrator, ptr_cpu_level()))
        return ptr_error_set(err, PTR_ERR_USAGE, "the %s integrator cannot run at CPU level %s",
                             ptr_integrator_name(integrator),
                             ptr_cpu_level_name(ptr_cpu_level()));
    if (job.paths.region.x1 == 0)
        return ptr_error_set(err, PTR_ERR_USAGE, "the region lies outside the %dx%d image",
                             settings->width, settings->height);
    if (!ptr_view_init(&job.paths.view, &scene->camera, settings->width, settings->height))
        return ptr_error_set(err, PTR_ERR_SCENE_INVALID,
                             "camera is degenerate (look-from equals look-at, up along the view, "
                             "field of view outside (0, 180) degrees, or bad focus distance/aperture)");
    PtrResult lights_res = ptr_lights_init(&job.paths.lights, scene, err);
    if (lights_res != PTR_OK)
        return lights_res;
    job.paths.sample_lights = settings->direct_lighting == PTR_ON && job.paths.lights.count > 0;
    job.tiles_x = (job.paths.region.x1 - job.paths.region.x0 + PTR_TILE_SIZE - 1) / PTR_TILE_SIZE;
    int tiles_y = (job.paths.region.y1 - job.paths.region.y0 + PTR_TILE_SIZE - 1) / PTR_TILE_SIZE;
    job.tile_count = job.tiles_x * tiles_y;
    atomic_init(&job.next_tile, 0);
    atomic_init(&job.tiles_done, 0);

    int threads = ptr_thread_count(settings->threads);
    if (threads > job.tile_count)
        threads = job.tile_count;
    Worker *workers = calloc((size_t)threads, sizeof *workers);
    if (!workers) {
        ptr_lights_free(&job.paths.lights);
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
    const double end = ptr_now_seconds(), seconds = end - start;
    double idle = 0.0;
    for (int i = 0; i < started; i++)
        idle += end - workers[i].finished;
    free(workers);
    ptr_lights_free(&job.paths.lights);
    pthread_cond_destroy(&job.all_done);
    pthread_mutex_destroy(&job.lock);
    if (tick)
        tick(user, 1.0);
    if (stats)
        *stats = (PtrRenderStats){ .seconds = seconds, .rays = rays,
                                   .threads = started ? started : 1, .idle_seconds = idle };
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
    size_t stride = ptr_accum_stride(settings->passes);
    double *acc = ptr_accum_alloc(pixels, stride);
    if (!acc)
        return ptr_error_set(err, PTR_ERR_NOMEM, "cannot allocate a %dx%d image",
                             r.x1 - r.x0, r.y1 - r.y0);
    PtrResult res = ptr_render_samples(scene, accel, settings, 0, settings->samples, acc, NULL,
                                       NULL, stats, err);
    if (res == PTR_OK)
        ptr_accum_resolve(acc, pixels, stride, rgb, NULL, NULL);
    ptr_accum_free(acc, pixels, stride);
    return res;
}
