/* The live module's session: the latest image under a lock, and the
 * encoder, a thread that turns it into the PNG a page shows, only while a
 * page is open and at most FRAMES_PER_SECOND times a second. */
#define _GNU_SOURCE /* pthread_setname_np */
#include "live/live_module.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

#include "base/version.h"

enum { FRAMES_PER_SECOND = 4, VIEW_PIXELS = 4096, ENCODER_NICE = 10 };
/* At the end, for a page to hear the last state and fetch the last image,
 * then for its event stream to end and the image to leave: each wait at
 * most this long. */
static const double linger_seconds = 1.0;

double ptr_live_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

void ptr_live_wait(PtrLiveSession *s, double seconds)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    double whole = floor(seconds);
    t.tv_sec += (time_t)whole;
    t.tv_nsec += (long)((seconds - whole) * 1e9);
    if (t.tv_nsec >= 1000000000L) {
        t.tv_sec++;
        t.tv_nsec -= 1000000000L;
    }
    pthread_cond_timedwait(&s->changed, &s->lock, &t);
}

PtrResult ptr_live_parse_address(const char *option, const char *text, char *host,
                                 size_t host_size, char *port, size_t port_size, PtrError *err)
{
    const char *colon = strrchr(text, ':');
    const char *p = colon ? colon + 1 : text;
    size_t host_len = colon ? (size_t)(colon - text) : 0;
    const char *h = text;
    if (host_len >= 2 && h[0] == '[' && h[host_len - 1] == ']') {
        h++;
        host_len -= 2;
    }
    char *end;
    errno = 0;
    unsigned long n = strtoul(p, &end, 10);
    if (*p < '0' || *p > '9' || *end || errno || n > 65535 || (colon && host_len == 0) ||
        host_len >= host_size || strlen(p) >= port_size)
        return ptr_error_set(
            err, PTR_ERR_USAGE,
            "%s: '%s' is not [HOST:]PORT (a port from 0 to 65535) (see ptr --help)", option, text);
    if (colon) {
        memcpy(host, h, host_len);
        host[host_len] = '\0';
    } else {
        snprintf(host, host_size, "127.0.0.1");
    }
    snprintf(port, port_size, "%lu", n);
    return PTR_OK;
}

/* Scene-linear to the view, then to 8 bits as an 8-bit output is rounded. */
static unsigned char *view_to_bytes(PtrLiveSession *s, float *rgb, size_t pixels, float stops)
{
    unsigned char *bytes = malloc(pixels * 3);
    if (!bytes)
        return NULL;
    /* In pieces that stay in cache: OpenColorIO works a row at a time, in a
     * buffer of its own as long as the row (500x500 pixels: 6 to 10 ms of
     * CPU in pieces of 4096, 13 to 22 ms in one). */
    for (size_t at = 0; at < pixels; at += VIEW_PIXELS) {
        size_t n = pixels - at < VIEW_PIXELS ? pixels - at : VIEW_PIXELS;
        if (s->options.view(s->options.view_user, rgb + 3 * at, n, stops) != 0) {
            free(bytes);
            return NULL;
        }
    }
    for (size_t i = 0; i < pixels * 3; i++) {
        float v = rgb[i];
        v = v > 0.0f ? (v < 1.0f ? v : 1.0f) : 0.0f; /* NaN to 0 */
        bytes[i] = (unsigned char)(v * 255.0f + 0.5f);
    }
    return bytes;
}

/* The image a page is to see (the lock held): the newest denoised frame
 * while the preview is on and there is one of this render, else the newest
 * frame; *frame is its number, *denoised whether it is denoised. */
static const float *shown(const PtrLiveSession *s, uint64_t *frame, int *denoised)
{
    *denoised = s->preview_denoised && s->denoised_frame > 0;
    *frame = *denoised ? s->denoised_frame : s->frame_version;
    return *denoised ? s->denoised : s->frame;
}

static int encoding_wanted(const PtrLiveSession *s)
{
    uint64_t frame;
    int denoised;
    shown(s, &frame, &denoised);
    return s->pages > 0 && s->frame && s->frame_version > 0 &&
           (s->png_frame != frame || s->png_denoised != denoised ||
            s->png_stops != s->stops_version);
}

static void *encode_loop(void *arg)
{
    PtrLiveSession *s = arg;
    pthread_setname_np(pthread_self(), "ptr-live-encode");
    /* Behind the render's threads when they want every core: a frame waits
     * rather than the render. */
    setpriority(PRIO_PROCESS, (id_t)syscall(SYS_gettid), ENCODER_NICE);
    float *work = NULL;
    size_t work_capacity = 0;
    double last = -1e9;
    pthread_mutex_lock(&s->lock);
    while (!s->stopping) {
        if (!encoding_wanted(s)) {
            ptr_live_wait(s, 1.0);
            continue;
        }
        double wait = last + 1.0 / FRAMES_PER_SECOND - ptr_live_now();
        if (wait > 0) {
            ptr_live_wait(s, wait);
            continue;
        }
        size_t floats = (size_t)s->width * (size_t)s->height * 3;
        if (floats > work_capacity) {
            free(work);
            work = malloc(floats * sizeof *work);
            work_capacity = work ? floats : 0;
            if (!work) {
                ptr_live_wait(s, 1.0); /* out of memory: no picture this time */
                continue;
            }
        }
        uint64_t frame;
        int denoised;
        memcpy(work, shown(s, &frame, &denoised), floats * sizeof *work);
        int width = s->width, height = s->height;
        uint64_t stops_version = s->stops_version;
        float stops = s->stops;
        pthread_mutex_unlock(&s->lock);

        last = ptr_live_now();
        unsigned char *bytes = view_to_bytes(s, work, floats / 3, stops);
        size_t size = 0;
        unsigned char *png = bytes ? ptr_live_png_encode(bytes, width, height, &size) : NULL;
        free(bytes);

        pthread_mutex_lock(&s->lock);
        /* A failure marks the frame as done: the next frame tries again. */
        s->png_frame = frame;
        s->png_denoised = denoised;
        s->png_stops = stops_version;
        if (png) {
            free(s->png);
            s->png = png;
            s->png_size = size;
            s->png_id++;
            s->event++;
            pthread_cond_broadcast(&s->changed);
        }
    }
    pthread_mutex_unlock(&s->lock);
    free(work);
    return NULL;
}

static void session_free(PtrLiveSession *s)
{
    pthread_cond_destroy(&s->changed);
    pthread_mutex_destroy(&s->lock);
    free(s->frame);
    free(s->denoised);
    free(s->png);
    free(s);
}

static void session_stop(PtrLiveSession *s)
{
    if (!s)
        return;
    pthread_mutex_lock(&s->lock);
    /* An open page gets the chance to hear the last state and fetch the
     * last image. */
    double deadline = ptr_live_now() + linger_seconds;
    while (s->pages > 0 && ptr_live_now() < deadline &&
           ((s->frame_version > 0 && s->served_frame != s->frame_version) ||
            ptr_live_http_pages_behind(s)))
        ptr_live_wait(s, deadline - ptr_live_now());
    s->stopping = 1;
    pthread_cond_broadcast(&s->changed);
    /* The event streams send what they have not sent yet, then end, and the
     * last image may still be on its way: let both finish before the server
     * closes their connections. */
    deadline = ptr_live_now() + linger_seconds;
    while ((s->pages > 0 || s->frames_sending > 0) && ptr_live_now() < deadline)
        ptr_live_wait(s, deadline - ptr_live_now());
    pthread_mutex_unlock(&s->lock);
    if (s->encoder_started)
        pthread_join(s->encoder, NULL);
    ptr_live_tev_stop(s);
    ptr_live_http_stop(s);
    session_free(s);
}

static PtrResult session_start(const PtrLiveOptions *options, PtrLiveSession **out,
                               PtrError *err)
{
    PtrLiveSession *s = calloc(1, sizeof *s);
    if (!s)
        return ptr_error_set(err, PTR_ERR_NOMEM, "out of memory for the live view");
    s->options = *options;
    s->listen_fd = -1;
    s->status.remaining = -1;
    pthread_mutex_init(&s->lock, NULL);
    ptr_live_cond_init(&s->changed);
    PtrResult res = options->http ? ptr_live_http_start(s, err) : PTR_OK;
    if (res != PTR_OK) {
        session_free(s);
        return res;
    }
    if (options->http) {
        if (pthread_create(&s->encoder, NULL, encode_loop, s)) {
            session_stop(s);
            return ptr_error_set(err, PTR_ERR_INTERNAL, "--live: cannot start a thread");
        }
        s->encoder_started = 1;
    }
    res = options->tev ? ptr_live_tev_start(s, err) : PTR_OK;
    if (res != PTR_OK) {
        session_stop(s);
        return res;
    }
    *out = s;
    return PTR_OK;
}

static const char *session_url(const PtrLiveSession *s)
{
    return s->url;
}

static void session_begin(PtrLiveSession *s, const char *scene, const char *output, int width,
                          int height)
{
    size_t floats = (size_t)width * (size_t)height * 3;
    pthread_mutex_lock(&s->lock);
    snprintf(s->scene, sizeof s->scene, "%s", scene);
    snprintf(s->output, sizeof s->output, "%s", output);
    if (floats > s->frame_capacity) {
        free(s->frame);
        s->frame = malloc(floats * sizeof *s->frame);
        s->frame_capacity = s->frame ? floats : 0;
    }
    if (s->frame)
        memset(s->frame, 0, floats * sizeof *s->frame);
    s->width = width;
    s->height = height;
    s->render++;
    s->render_frames = s->frame_version;
    s->denoised_frame = 0;
    s->status = (PtrLiveStatus){ .remaining = -1, .state = PTR_LIVE_RENDERING };
    s->event++;
    pthread_cond_broadcast(&s->changed);
    pthread_mutex_unlock(&s->lock);
}

static uint64_t session_frame(PtrLiveSession *s, const float *rgb, const PtrLiveStatus *status)
{
    pthread_mutex_lock(&s->lock);
    if (s->frame) {
        memcpy(s->frame, rgb, (size_t)s->width * (size_t)s->height * 3 * sizeof *rgb);
        s->frame_version++;
    }
    uint64_t frame = s->frame_version;
    s->status = *status;
    s->event++;
    pthread_cond_broadcast(&s->changed);
    pthread_mutex_unlock(&s->lock);
    return frame;
}

static int session_denoise_wanted(PtrLiveSession *s)
{
    pthread_mutex_lock(&s->lock);
    int wanted = (s->pages > 0 && s->preview_denoised) || (s->tev && s->options.tev_denoised);
    pthread_mutex_unlock(&s->lock);
    return wanted;
}

static void session_denoised(PtrLiveSession *s, uint64_t frame, const float *rgb)
{
    pthread_mutex_lock(&s->lock);
    size_t floats = (size_t)s->width * (size_t)s->height * 3;
    if (frame > s->render_frames && frame <= s->frame_version && frame > s->denoised_frame) {
        if (floats > s->denoised_capacity) {
            free(s->denoised);
            s->denoised = malloc(floats * sizeof *s->denoised);
            s->denoised_capacity = s->denoised ? floats : 0;
        }
        if (s->denoised) {
            memcpy(s->denoised, rgb, floats * sizeof *rgb);
            s->denoised_frame = frame;
            pthread_cond_broadcast(&s->changed);
        }
    }
    pthread_mutex_unlock(&s->lock);
}

static void session_end(PtrLiveSession *s, const PtrLiveStatus *status)
{
    pthread_mutex_lock(&s->lock);
    s->status = *status;
    s->event++;
    pthread_cond_broadcast(&s->changed);
    pthread_mutex_unlock(&s->lock);
}

__attribute__((visibility("default"))) const PtrLiveModule ptr_live_module_table = {
    .size = sizeof(PtrLiveModule),
    .version = PTR_VERSION,
    .start = session_start,
    .url = session_url,
    .begin = session_begin,
    .frame = session_frame,
    .denoise_wanted = session_denoise_wanted,
    .denoised = session_denoised,
    .end = session_end,
    .stop = session_stop,
};
