/* tev's side of the live view: a thread that connects to tev over TCP and
 * sends the image as tev's protocol defines it, as pbrt-v4 does: each
 * message is [uint32 length, itself included][uint8 type][payload],
 * little-endian, strings ending in a zero byte. CreateImage (type 4) names
 * the image and its channels; UpdateImage (type 3) sends one channel of a
 * tile as floats. After each pass (at most every 250 ms) only the tiles
 * that changed are sent, linear RGB; with tev_denoised, the newest denoised
 * frame too, as channels denoised.R/G/B (tev's layer "denoised"), once
 * there is one (the image is created again with them). A failed send
 * closes the connection; the next frame reconnects (at most once a
 * second), creating the image again, so a tev that restarts gets the whole
 * image. The render never waits for any of it. */
#define _GNU_SOURCE /* pthread_setname_np */
#include "live/live_module.h"

#include <errno.h>
#include <fcntl.h>
#include <netdb.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/time.h>
#include <unistd.h>

enum {
    TILE = 128,
    TYPE_UPDATE_IMAGE = 3,
    TYPE_CREATE_IMAGE = 4,
    CONNECT_TIMEOUT_MS = 500,
    SEND_TIMEOUT_SECONDS = 2,
};
static const double send_interval = 0.25, reconnect_interval = 1.0;

/* The channels of the image, in the order of current's floats. */
static const char *const channel_names[] = { "R", "G", "B", "denoised.R", "denoised.G",
                                             "denoised.B" };

struct LiveTev {
    char host[256], port[16];
    pthread_t thread;
    int fd;
    uint64_t sent_frame;  /* frame_version last sent */
    uint64_t sent_denoised; /* denoised_frame last sent */
    uint64_t created;     /* the render whose image tev has */
    float *current, *previous; /* what this frame is, what tev has (NULL: nothing) */
    size_t capacity;
    int width, height;
    int channels;         /* 3, or 6 with the denoised frame */
    int created_channels; /* those of the image tev has */
    char name[256];
    unsigned char *message;
    size_t message_capacity;
};

typedef struct Writer {
    unsigned char *at;
} Writer;

static void put_bytes(Writer *w, const void *bytes, size_t n)
{
    memcpy(w->at, bytes, n);
    w->at += n;
}

static void put_u32(Writer *w, uint32_t v)
{
    unsigned char b[4] = { (unsigned char)v, (unsigned char)(v >> 8), (unsigned char)(v >> 16),
                           (unsigned char)(v >> 24) };
    put_bytes(w, b, 4);
}

static void put_string(Writer *w, const char *text)
{
    put_bytes(w, text, strlen(text) + 1);
}

static void put_float(Writer *w, float f)
{
    uint32_t bits;
    memcpy(&bits, &f, 4);
    put_u32(w, bits);
}

static int send_all(int fd, const unsigned char *bytes, size_t n)
{
    while (n > 0) {
        ssize_t sent = send(fd, bytes, n, MSG_NOSIGNAL);
        if (sent < 0 && errno == EINTR)
            continue;
        if (sent <= 0)
            return 0;
        bytes += sent;
        n -= (size_t)sent;
    }
    return 1;
}

static unsigned char *message_buffer(LiveTev *t, size_t size)
{
    if (size > t->message_capacity) {
        free(t->message);
        t->message = malloc(size);
        t->message_capacity = t->message ? size : 0;
    }
    return t->message;
}

/* The start every message has: its size (the whole message's), its type,
 * whether tev should bring the image to the front, and the image's name. */
static size_t header_size(const LiveTev *t)
{
    return 4 + 1 + 1 + strlen(t->name) + 1;
}

static void put_header(Writer *w, const LiveTev *t, size_t size, unsigned char type,
                       unsigned char grab_focus)
{
    put_u32(w, (uint32_t)size);
    put_bytes(w, &type, 1);
    put_bytes(w, &grab_focus, 1);
    put_string(w, t->name);
}

static int send_create(LiveTev *t)
{
    size_t size = header_size(t) + 4 * 3;
    for (int c = 0; c < t->channels; c++)
        size += strlen(channel_names[c]) + 1;
    unsigned char *m = message_buffer(t, size);
    if (!m)
        return 0;
    Writer w = { m };
    put_header(&w, t, size, TYPE_CREATE_IMAGE, 1);
    put_u32(&w, (uint32_t)t->width);
    put_u32(&w, (uint32_t)t->height);
    put_u32(&w, (uint32_t)t->channels);
    for (int c = 0; c < t->channels; c++)
        put_string(&w, channel_names[c]);
    return send_all(t->fd, m, size);
}

static int send_tile(LiveTev *t, int x0, int y0, int w, int h)
{
    const size_t channels = (size_t)t->channels;
    for (size_t c = 0; c < channels; c++) {
        size_t size = header_size(t) + strlen(channel_names[c]) + 1 + 4 * 4 +
                      4 * (size_t)w * (size_t)h;
        unsigned char *m = message_buffer(t, size);
        if (!m)
            return 0;
        Writer wr = { m };
        put_header(&wr, t, size, TYPE_UPDATE_IMAGE, 0);
        put_string(&wr, channel_names[c]);
        put_u32(&wr, (uint32_t)x0);
        put_u32(&wr, (uint32_t)y0);
        put_u32(&wr, (uint32_t)w);
        put_u32(&wr, (uint32_t)h);
        for (int y = y0; y < y0 + h; y++)
            for (int x = x0; x < x0 + w; x++)
                put_float(&wr,
                          t->current[((size_t)y * (size_t)t->width + (size_t)x) * channels + c]);
        if (!send_all(t->fd, m, size))
            return 0;
    }
    return 1;
}

static int tile_changed(const LiveTev *t, int x0, int y0, int w, int h)
{
    if (!t->previous)
        return 1;
    for (int y = y0; y < y0 + h; y++) {
        size_t at = ((size_t)y * (size_t)t->width + (size_t)x0) * (size_t)t->channels;
        if (memcmp(t->current + at, t->previous + at,
                   (size_t)w * (size_t)t->channels * sizeof(float)))
            return 1;
    }
    return 0;
}

/* Sends the tiles of current that tev does not have; 0 if a send failed. */
static int send_changes(LiveTev *t)
{
    for (int y = 0; y < t->height; y += TILE)
        for (int x = 0; x < t->width; x += TILE) {
            int w = t->width - x < TILE ? t->width - x : TILE;
            int h = t->height - y < TILE ? t->height - y : TILE;
            if (tile_changed(t, x, y, w, h) && !send_tile(t, x, y, w, h))
                return 0;
        }
    return 1;
}

static void disconnect(LiveTev *t)
{
    if (t->fd >= 0)
        close(t->fd);
    t->fd = -1;
    t->created = 0;
}

/* A connection within CONNECT_TIMEOUT_MS, else -1. */
static int connect_to(const char *host, const char *port)
{
    struct addrinfo hints = { .ai_socktype = SOCK_STREAM, .ai_flags = AI_NUMERICSERV }, *list;
    if (getaddrinfo(host, port, &hints, &list))
        return -1;
    int fd = -1;
    for (struct addrinfo *a = list; a && fd < 0; a = a->ai_next) {
        fd = socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC | SOCK_NONBLOCK, a->ai_protocol);
        if (fd < 0)
            continue;
        int ok = connect(fd, a->ai_addr, a->ai_addrlen) == 0;
        if (!ok && errno == EINPROGRESS) {
            struct pollfd p = { .fd = fd, .events = POLLOUT };
            int error = 0;
            socklen_t len = sizeof error;
            ok = poll(&p, 1, CONNECT_TIMEOUT_MS) == 1 &&
                 !getsockopt(fd, SOL_SOCKET, SO_ERROR, &error, &len) && !error;
        }
        if (!ok) {
            close(fd);
            fd = -1;
        }
    }
    freeaddrinfo(list);
    if (fd >= 0) {
        fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) & ~O_NONBLOCK);
        struct timeval timeout = { SEND_TIMEOUT_SECONDS, 0 };
        setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &timeout, sizeof timeout);
    }
    return fd;
}

/* Copies the session's image, and its denoised frame if tev is to get it,
 * into current (the lock held): 0 if none. */
static int take_frame(PtrLiveSession *s, LiveTev *t)
{
    int channels = s->options.tev_denoised && s->denoised_frame > 0 ? 6 : 3;
    size_t pixels = (size_t)s->width * (size_t)s->height, floats = pixels * (size_t)channels;
    if (!s->frame || s->frame_version == 0 || floats == 0)
        return 0;
    if (floats > t->capacity) {
        free(t->current);
        free(t->previous);
        t->current = malloc(floats * sizeof(float));
        t->previous = malloc(floats * sizeof(float));
        t->capacity = t->current && t->previous ? floats : 0;
        if (!t->capacity)
            return 0;
        t->created = 0;
    }
    if (channels == 3) {
        memcpy(t->current, s->frame, floats * sizeof(float));
    } else {
        for (size_t i = 0; i < pixels; i++) {
            memcpy(t->current + 6 * i, s->frame + 3 * i, 3 * sizeof(float));
            memcpy(t->current + 6 * i + 3, s->denoised + 3 * i, 3 * sizeof(float));
        }
    }
    if (t->created != s->render || t->width != s->width || t->height != s->height ||
        t->created_channels != channels)
        t->created = 0; /* a new image for tev */
    t->width = s->width;
    t->height = s->height;
    t->channels = channels;
    const char *base = strrchr(s->output, '/');
    snprintf(t->name, sizeof t->name, "%s", base ? base + 1 : s->output);
    return 1;
}

static void *send_loop(void *arg)
{
    PtrLiveSession *s = arg;
    pthread_setname_np(pthread_self(), "ptr-live-tev");
    LiveTev *t = s->tev;
    double last_send = -1e9, last_attempt = -1e9;
    pthread_mutex_lock(&s->lock);
    for (;;) {
        int pending = (s->frame_version != t->sent_frame && s->frame_version > 0) ||
                      (s->denoised_frame > 0 && s->denoised_frame != t->sent_denoised);
        if (s->stopping && (!pending || t->fd < 0))
            break; /* the last frame is sent, or there is no tev to send it to */
        double now = ptr_live_now();
        double wait = !pending ? 1.0
                      : t->fd < 0 ? last_attempt + reconnect_interval - now
                                  : last_send + send_interval - now;
        if (wait > 0 && !s->stopping) {
            ptr_live_wait(s, wait);
            continue;
        }
        uint64_t render = s->render, frame = s->frame_version, denoised = s->denoised_frame;
        if (!take_frame(s, t)) {
            t->sent_frame = frame;
            t->sent_denoised = denoised;
            continue;
        }
        pthread_mutex_unlock(&s->lock);

        if (t->fd < 0) {
            last_attempt = ptr_live_now();
            t->fd = connect_to(t->host, t->port);
        }
        int ok = t->fd >= 0;
        if (ok && !t->created) {
            ok = send_create(t);
            t->created = ok ? render : 0;
            t->created_channels = t->channels;
            /* tev has nothing of this image yet */
            float *keep = t->previous;
            if (ok) {
                t->previous = NULL;
                ok = send_changes(t);
                t->previous = keep;
            }
        } else if (ok) {
            ok = send_changes(t);
        }
        last_send = ptr_live_now();
        if (ok) {
            float *swap = t->previous;
            t->previous = t->current;
            t->current = swap;
        } else {
            disconnect(t);
        }

        pthread_mutex_lock(&s->lock);
        if (ok) {
            t->sent_frame = frame;
            t->sent_denoised = denoised;
        } else if (s->stopping)
            break;
    }
    pthread_mutex_unlock(&s->lock);
    return NULL;
}

PtrResult ptr_live_tev_start(PtrLiveSession *s, PtrError *err)
{
    LiveTev *t = calloc(1, sizeof *t);
    if (!t)
        return ptr_error_set(err, PTR_ERR_NOMEM, "out of memory for --tev");
    t->fd = -1;
    PtrResult res = ptr_live_parse_address("--tev", s->options.tev, t->host, sizeof t->host,
                                           t->port, sizeof t->port, err);
    if (res != PTR_OK) {
        free(t);
        return res;
    }
    s->tev = t;
    if (pthread_create(&t->thread, NULL, send_loop, s)) {
        s->tev = NULL;
        free(t);
        return ptr_error_set(err, PTR_ERR_INTERNAL, "--tev: cannot start a thread");
    }
    return PTR_OK;
}

void ptr_live_tev_stop(PtrLiveSession *s)
{
    LiveTev *t = s->tev;
    if (!t)
        return;
    pthread_join(t->thread, NULL);
    disconnect(t);
    free(t->current);
    free(t->previous);
    free(t->message);
    free(t);
    s->tev = NULL;
}
