/* What the live module's files share (the module only: live.h is the
 * interface ptr sees). One session holds the latest image under one lock;
 * the encoder (live_module.c), the server's connections (live_http.c) and
 * tev's sender (live_tev.c) read it there and do their work outside it. */
#ifndef PTR_LIVE_MODULE_H
#define PTR_LIVE_MODULE_H

#include <pthread.h>
#include <stddef.h>
#include <stdint.h>
#include <sys/socket.h>
#include <time.h>

#include "live/live.h"

typedef struct LiveTev LiveTev;

struct PtrLiveSession {
    PtrLiveOptions options;
    pthread_mutex_t lock;
    pthread_cond_t changed; /* broadcast on every change below */
    int stopping;

    /* The render under way, or the last one. */
    char scene[256], output[256];
    int width, height;
    uint64_t render;        /* begin() calls so far */
    float *frame;           /* width x height RGB, scene-linear; NULL before a frame */
    size_t frame_capacity;  /* floats */
    uint64_t frame_version; /* frame() calls so far, over all renders */
    uint64_t render_frames; /* frame_version when the render began: its frames are above */
    float *denoised;        /* the newest denoised frame of this render, width x height RGB */
    size_t denoised_capacity; /* floats */
    uint64_t denoised_frame; /* the frame it is of; 0: none of this render */
    PtrLiveStatus status;
    uint64_t event;         /* changes a page should hear about */

    /* The page: open event streams, its exposure, its denoised preview
     * (on or off), and the PNG of the view. */
    int pages;
    void *streams;          /* live_http.c's list of them */
    float stops;
    uint64_t stops_version;
    int preview_denoised;   /* the page's toggle: show denoised frames when there are */
    unsigned char *png;
    size_t png_size;
    uint64_t png_id;        /* encodings so far: the page asks for /frame.png?id */
    uint64_t png_frame, png_stops; /* the frame_version and stops_version it shows */
    int png_denoised;       /* it shows the denoised image of png_frame */
    uint64_t served_frame;  /* the newest frame_version a page has fetched */
    int frames_sending;     /* /frame.png responses not yet sent in full */
    pthread_t encoder;
    int encoder_started;

    /* The server. */
    void *daemon;
    void *http;             /* live_http.c's connections and their deadlines */
    int listen_fd;
    char url[128];

    LiveTev *tev;
};

/* "[HOST:]PORT" ("[::1]:PORT" for IPv6) split into host (default
 * 127.0.0.1) and port: PTR_ERR_USAGE, naming option, if the text is not
 * that. */
PtrResult ptr_live_parse_address(const char *option, const char *text, char *host,
                                 size_t host_size, char *port, size_t port_size, PtrError *err);

/* Seconds on a steady clock. */
double ptr_live_now(void);

/* Waits on the session's condition for at most seconds (the lock held). */
void ptr_live_wait(PtrLiveSession *s, double seconds);

/* The server (live_http.c): binds options->http and starts serving. */
PtrResult ptr_live_http_start(PtrLiveSession *s, PtrError *err);
void ptr_live_http_stop(PtrLiveSession *s);
/* Whether an open page has yet to hear of the latest change (the lock held). */
int ptr_live_http_pages_behind(const PtrLiveSession *s);

/* tev's sender (live_tev.c): a thread that connects to options->tev,
 * reconnecting when the connection fails, and sends changed tiles. */
PtrResult ptr_live_tev_start(PtrLiveSession *s, PtrError *err);
void ptr_live_tev_stop(PtrLiveSession *s);

/* 8-bit RGB rows to a PNG in memory (live_png.c): malloc'ed, NULL on failure. */
unsigned char *ptr_live_png_encode(const unsigned char *rgb, int width, int height,
                                   size_t *size);

/* The page (src/live/page.html, embedded at build time). */
extern const char ptr_live_page[];

/* A condition variable whose timed waits count on CLOCK_MONOTONIC, which
 * a change of the wall clock does not move. */
static inline void ptr_live_cond_init(pthread_cond_t *cond)
{
    pthread_condattr_t attr;
    pthread_condattr_init(&attr);
    pthread_condattr_setclock(&attr, CLOCK_MONOTONIC);
    pthread_cond_init(cond, &attr);
    pthread_condattr_destroy(&attr);
}

#endif /* PTR_LIVE_MODULE_H */
