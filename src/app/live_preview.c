#define _GNU_SOURCE /* pthread_setname_np */
#include "app/live_preview.h"

#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

#include "app/signals.h"
#include "denoise/conv.h"
#include "denoise/denoise.h"
#include "render/film.h"

/* The passes the preview renders itself: a few samples give the edges
 * their antialiasing, at a few percent of a render of hundreds. The
 * niceness is the live encoder's: a frame waits rather than the render. */
enum { GUIDE_SAMPLES = 4, PREVIEW_NICE = 10 };
/* The share of the cores ptr may run on that the preview takes at most, over time:
 * a niceness alone bounds it only against the render's threads, not when
 * they wait (between passes, for the last tiles) or compete with other
 * processes, where the preview took a quarter of ptr's CPU time. After a
 * frame that cost it c seconds of CPU, it rests until c is this share of
 * the cores' time since the frame began. */
static const double cpu_share = 0.05;

/* A frame handed over: colour, then albedo, then normal, 3 floats a pixel
 * each, in one buffer that moves between its owners whole. */
typedef struct Frame {
    float *data;
    size_t capacity;   /* floats */
    size_t width, pixels;
    uint64_t number;   /* the live module's; 0: none */
    uint64_t render;   /* ptr_live_preview_begin calls before it */
    int has_passes;    /* its albedo and normal are the film's */
} Frame;

struct PtrLivePreview {
    PtrDenoiser *denoiser;
    PtrLivePreviewDone done;
    void *user;
    pthread_t thread;
    pthread_mutex_t lock;
    pthread_cond_t changed;
    int stopping;
    Frame filling;     /* the render's thread's, outside the lock */
    Frame pending;     /* the newest handed over; number 0 once taken */
    /* The render under way: what its passes are rendered from; scene NULL
     * once it ended. */
    uint64_t render;
    const PtrScene *scene;
    const PtrAccel *accel;
    PtrRenderSettings settings;
    uint32_t first_sample, guide_samples;
    int guides_busy;   /* the preview's thread reads scene and accel */
};

/* The preview's thread's own: the frame it denoises, the passes it
 * rendered, the result, and the CPU time they took. */
typedef struct Work {
    double cpu_seconds;
    Frame frame;
    float *guides;     /* albedo, then normal, of guides_render */
    size_t guides_capacity; /* floats */
    uint64_t guides_render; /* 0: none */
    float *out;
    size_t out_capacity; /* floats */
} Work;

/* Makes room for floats floats in *buffer (of *capacity): 0 if memory ran
 * out, the buffer then freed. */
static int reserve(float **buffer, size_t *capacity, size_t floats)
{
    if (floats <= *capacity)
        return 1;
    free(*buffer);
    *buffer = malloc(floats * sizeof **buffer);
    *capacity = *buffer ? floats : 0;
    return *buffer != NULL;
}

/* The albedo and normal of the render's region from its first samples, on
 * one thread, into w->guides: 0 on failure. */
static int render_guides(Work *w, const PtrScene *scene, const PtrAccel *accel,
                         const PtrRenderSettings *render, uint32_t first, uint32_t samples)
{
    PtrRenderSettings settings = *render;
    settings.passes = 1;
    settings.threads = 1;
    settings.noise_threshold = 0; /* every pixel its samples */
    PtrRegion r = ptr_render_region(&settings);
    size_t pixels = (size_t)(r.x1 - r.x0) * (size_t)(r.y1 - r.y0);
    double *film = ptr_accum_alloc(pixels, PTR_ACCUM_STRIDE_PASSES);
    if (!film || !reserve(&w->guides, &w->guides_capacity, pixels * 6)) {
        ptr_accum_free(film, pixels, PTR_ACCUM_STRIDE_PASSES);
        return 0;
    }
    PtrRenderStats stats;
    int ok = ptr_render_samples(scene, accel, &settings, first, samples, film, NULL, NULL,
                                &stats, NULL) == PTR_OK;
    w->cpu_seconds += ok ? stats.seconds : 0; /* one thread, busy throughout */
    if (ok)
        ptr_accum_resolve_passes(film, pixels, w->guides, w->guides + 3 * pixels);
    ptr_accum_free(film, pixels, PTR_ACCUM_STRIDE_PASSES);
    return ok;
}

/* The passes for w->frame (the lock held on entry and exit): the film's,
 * or those rendered for its render, rendered now if the render is still
 * under way. */
static const float *guides_for(PtrLivePreview *p, Work *w)
{
    Frame *f = &w->frame;
    if (f->has_passes)
        return f->data + 3 * f->pixels;
    if (w->guides_render != f->render) {
        if (p->render != f->render || !p->scene)
            return NULL; /* its render ended: the next one's frames are due */
        p->guides_busy = 1;
        const PtrScene *scene = p->scene;
        const PtrAccel *accel = p->accel;
        PtrRenderSettings settings = p->settings;
        uint32_t first = p->first_sample, samples = p->guide_samples;
        pthread_mutex_unlock(&p->lock);
        int ok = render_guides(w, scene, accel, &settings, first, samples);
        pthread_mutex_lock(&p->lock);
        p->guides_busy = 0;
        pthread_cond_broadcast(&p->changed);
        w->guides_render = ok ? f->render : 0;
        if (!ok)
            return NULL;
    }
    return w->guides;
}

/* Denoises w->frame with the passes given, on this thread, and hands the
 * result over. */
static void denoise_frame(PtrLivePreview *p, Work *w, const float *guides)
{
    const Frame *f = &w->frame;
    if (!reserve(&w->out, &w->out_capacity, f->pixels * 3))
        return;
    const PtrDenoiseInput input = {
        .color = f->data, .albedo = guides, .normal = guides + 3 * f->pixels,
        .color_stride = 3, .albedo_stride = 3, .normal_stride = 3,
        .width = f->width, .height = f->pixels / f->width,
    };
    if (ptr_denoise(p->denoiser, &input, 1, w->out, 3, NULL) == PTR_OK)
        p->done(p->user, f->number, w->out);
}

static double thread_cpu_seconds(void)
{
    struct timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Waits until ptr_now_seconds() reaches until, or stopping (the lock
 * held). */
static void rest_until(PtrLivePreview *p, double until)
{
    struct timespec t;
    double whole = floor(until);
    t.tv_sec = (time_t)whole;
    t.tv_nsec = (long)((until - whole) * 1e9);
    while (!p->stopping && ptr_now_seconds() < until)
        pthread_cond_timedwait(&p->changed, &p->lock, &t);
}

static void *preview_loop(void *arg)
{
    PtrLivePreview *p = arg;
    pthread_setname_np(pthread_self(), "ptr-live-oidn");
    setpriority(PRIO_PROCESS, (id_t)syscall(SYS_gettid), PREVIEW_NICE);
    const double cores = ptr_usable_cpus();
    Work w = { 0 };
    pthread_mutex_lock(&p->lock);
    /* Stopping, a frame still waiting is denoised (the render's last),
     * unless the process was asked to stop. */
    while (!p->stopping || (p->pending.number && !ptr_stop_requested)) {
        if (!p->pending.number) {
            pthread_cond_wait(&p->changed, &p->lock);
            continue;
        }
        Frame taken = p->pending;
        p->pending = w.frame;
        p->pending.number = 0;
        w.frame = taken;
        double start = ptr_now_seconds(), cpu_start = thread_cpu_seconds();
        w.cpu_seconds = 0;
        const float *guides = guides_for(p, &w);
        pthread_mutex_unlock(&p->lock);
        if (guides)
            denoise_frame(p, &w, guides);
        w.cpu_seconds += thread_cpu_seconds() - cpu_start;
        pthread_mutex_lock(&p->lock);
        rest_until(p, start + w.cpu_seconds / (cpu_share * cores));
    }
    pthread_mutex_unlock(&p->lock);
    free(w.frame.data);
    free(w.guides);
    free(w.out);
    return NULL;
}

PtrResult ptr_live_preview_new(PtrCpuLevel level, PtrLivePreviewDone done, void *user,
                               PtrLivePreview **out, PtrError *err)
{
    /* The C reference runs the network at a fraction of a GFLOP/s: minutes
     * a frame, and a stop that waits for the frame under way. */
    PtrConvTable conv;
    ptr_conv_init_level(&conv, level);
    if (conv.conv3x3 == ptr_conv3x3_c)
        return ptr_error_set(err, PTR_ERR_USAGE,
                             "no vector convolution at CPU level '%s' (AVX2 and up)",
                             ptr_cpu_level_name(level));
    PtrLivePreview *p = calloc(1, sizeof *p);
    if (!p)
        return ptr_error_set(err, PTR_ERR_NOMEM, "out of memory for the denoised preview");
    PtrResult res = ptr_denoiser_new(PTR_DENOISE_FAST, NULL, level, &p->denoiser, err);
    if (res != PTR_OK) {
        free(p);
        return res;
    }
    p->done = done;
    p->user = user;
    pthread_mutex_init(&p->lock, NULL);
    /* Timed waits on the clock ptr_now_seconds reads. */
    pthread_condattr_t attr;
    pthread_condattr_init(&attr);
    pthread_condattr_setclock(&attr, CLOCK_MONOTONIC);
    pthread_cond_init(&p->changed, &attr);
    pthread_condattr_destroy(&attr);
    if (pthread_create(&p->thread, NULL, preview_loop, p)) {
        pthread_cond_destroy(&p->changed);
        pthread_mutex_destroy(&p->lock);
        ptr_denoiser_free(p->denoiser);
        free(p);
        return ptr_error_set(err, PTR_ERR_INTERNAL,
                             "cannot start the denoised preview's thread");
    }
    *out = p;
    return PTR_OK;
}

void ptr_live_preview_free(PtrLivePreview *p)
{
    if (!p)
        return;
    pthread_mutex_lock(&p->lock);
    p->stopping = 1;
    pthread_cond_broadcast(&p->changed);
    pthread_mutex_unlock(&p->lock);
    pthread_join(p->thread, NULL);
    pthread_cond_destroy(&p->changed);
    pthread_mutex_destroy(&p->lock);
    ptr_denoiser_free(p->denoiser);
    free(p->filling.data);
    free(p->pending.data);
    free(p);
}

void ptr_live_preview_begin(PtrLivePreview *p, const PtrScene *scene, const PtrAccel *accel,
                            const PtrRenderSettings *settings, uint32_t first_sample,
                            uint32_t samples)
{
    pthread_mutex_lock(&p->lock);
    p->render++;
    p->scene = scene;
    p->accel = accel;
    p->settings = *settings;
    p->first_sample = first_sample;
    p->guide_samples = samples < GUIDE_SAMPLES ? samples : GUIDE_SAMPLES;
    p->pending.number = 0; /* the last render's, never to be shown */
    pthread_mutex_unlock(&p->lock);
}

void ptr_live_preview_frame(PtrLivePreview *p, uint64_t frame, const float *rgb,
                            const double *film, size_t pixels, size_t stride)
{
    Frame *f = &p->filling;
    if (!reserve(&f->data, &f->capacity, pixels * 9))
        return;
    PtrRegion r = ptr_render_region(&p->settings);
    f->width = (size_t)(r.x1 - r.x0);
    f->pixels = pixels;
    f->number = frame;
    f->render = p->render;
    f->has_passes = stride == PTR_ACCUM_STRIDE_PASSES;
    memcpy(f->data, rgb, pixels * 3 * sizeof *rgb);
    if (f->has_passes)
        ptr_accum_resolve_passes(film, pixels, f->data + 3 * pixels, f->data + 6 * pixels);
    pthread_mutex_lock(&p->lock);
    Frame dropped = p->pending; /* not taken yet: older than this one */
    p->pending = *f;
    *f = dropped;
    pthread_cond_broadcast(&p->changed);
    pthread_mutex_unlock(&p->lock);
}

void ptr_live_preview_end(PtrLivePreview *p)
{
    pthread_mutex_lock(&p->lock);
    p->scene = NULL;
    p->accel = NULL;
    while (p->guides_busy)
        pthread_cond_wait(&p->changed, &p->lock);
    pthread_mutex_unlock(&p->lock);
}
