/* The live view: what a render shows while it refines, in a browser (an
 * HTTP server, --live) and in tev (a TCP client, --tev). The server and the
 * client live in a module of their own (live_module.c, live_http.c,
 * live_tev.c, live_png.c: lib/ptr/ptr_live.so, linking libmicrohttpd and
 * libpng), which live_loader.c loads only when a render asks for a live
 * view: a render without one never maps them.
 *
 * The renderer hands each pass's image (scene-linear RGB) to frame(), which
 * copies it under a lock and returns: everything else (the view transform,
 * PNG encoding, sending) happens on the module's own threads, and only while
 * a page is open or tev is connected. While a page has its denoised preview
 * on (or tev is to get a denoised layer), the renderer denoises frames on a
 * thread of its own and hands the results to denoised(): the module holds
 * no denoiser. */
#ifndef PTR_LIVE_H
#define PTR_LIVE_H

#include <stddef.h>
#include <stdint.h>

#include "base/result.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct PtrLiveSession PtrLiveSession;

/* Where a render stands, after a pass or at its end. */
typedef struct PtrLiveStatus {
    uint32_t samples_done, samples_total;
    double elapsed;   /* seconds since the render started */
    double remaining; /* seconds, estimated; negative: unknown */
    double mrays_per_second;
    int state;        /* PTR_LIVE_RENDERING, PTR_LIVE_DONE or PTR_LIVE_FAILED */
} PtrLiveStatus;

enum { PTR_LIVE_RENDERING, PTR_LIVE_DONE, PTR_LIVE_FAILED };

typedef struct PtrLiveOptions {
    const char *http; /* --live [HOST:]PORT, or NULL */
    const char *tev;  /* --tev [HOST:]PORT, or NULL */
    /* Transforms rgb (pixels RGB triples, scene-linear) in place to the
     * output's display, view and look, with stops of exposure on top of the
     * output's; called on the module's threads, so it must be thread-safe.
     * Returns 0 on success. */
    int (*view)(void *user, float *rgb, size_t pixels, float stops);
    void *view_user;
    /* Whether tev gets the denoised image as a layer "denoised" beside the
     * noisy RGB (the render denoises its output). */
    int tev_denoised;
} PtrLiveOptions;

#define PTR_LIVE_MODULE_SYMBOL "ptr_live_module_table"

/* The module's one exported symbol. */
typedef struct PtrLiveModule {
    /* sizeof(PtrLiveModule) and PTR_VERSION as the module was built. */
    size_t size;
    const char *version;

    /* Binds the server, starts the threads, and hands the session over in
     * *out: PTR_OK, else PTR_ERR_USAGE for an address that cannot be used (a
     * port in use, an unknown host), PTR_ERR_NOMEM, PTR_ERR_INTERNAL. */
    PtrResult (*start)(const PtrLiveOptions *options, PtrLiveSession **out, PtrError *err);
    /* The page's address, "http://HOST:PORT/" ("" without --live). */
    const char *(*url)(const PtrLiveSession *session);
    /* A render starts: the image it makes is width x height. */
    void (*begin)(PtrLiveSession *session, const char *scene, const char *output, int width,
                  int height);
    /* The image after a pass (width x height RGB of begin, scene-linear):
     * copied, never kept. Returns its number, which names its denoised
     * image. */
    uint64_t (*frame)(PtrLiveSession *session, const float *rgb, const PtrLiveStatus *status);
    /* Whether a denoised image of the frames is wanted now: a page is open
     * with its preview on, or tev_denoised. */
    int (*denoise_wanted)(PtrLiveSession *session);
    /* The denoised image of the frame numbered frame (the RGB of frame(),
     * denoised): copied, never kept; ignored if it is of an earlier render
     * or older than the denoised image the module has. */
    void (*denoised)(PtrLiveSession *session, uint64_t frame, const float *rgb);
    /* The render ended (status->state says how); the page keeps its image. */
    void (*end)(PtrLiveSession *session, const PtrLiveStatus *status);
    /* Lets open pages fetch the last image (a second or two at most), stops the
     * threads and closes every connection. */
    void (*stop)(PtrLiveSession *session);
} PtrLiveModule;

/* The module into *out, loaded now (live_loader.c), for the caller to keep
 * (it stays loaded for the process): PTR_OK, else PTR_ERR_INSTALL or
 * PTR_ERR_NOMEM. */
PtrResult ptr_live_module(const PtrLiveModule **out, PtrError *err);

#ifdef __cplusplus
}
#endif

#endif /* PTR_LIVE_H */
