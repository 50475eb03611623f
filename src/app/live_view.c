#include "app/live_view.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "app/live_preview.h"
#include "live/live.h"
#include "render/film.h"

struct PtrLiveView {
    const PtrLiveModule *module;
    PtrLiveSession *session;
    PtrLivePreview *preview; /* NULL: no denoised preview (no weights) */
    float *scratch;          /* the resolved film of the render under way */
    size_t scratch_pixels;
    PtrLiveStatus last;
};

/* The page's view: the output's transform, with the page's exposure on top
 * (a gain in scene-linear, before the view, as --exposure is). */
static int apply_view(void *user, float *rgb, size_t pixels, float stops)
{
    if (stops != 0.0f) {
        float gain = exp2f(stops);
        for (size_t i = 0; i < pixels * 3; i++)
            rgb[i] *= gain;
    }
    PtrError err;
    return ptr_color_apply(user, rgb, pixels, &err) == PTR_OK ? 0 : -1;
}

static void hand_denoised(void *user, uint64_t frame, const float *rgb)
{
    PtrLiveView *view = user;
    view->module->denoised(view->session, frame, rgb);
}

PtrResult ptr_live_view_open(const PtrOptions *o, const PtrColor *color, PtrLiveView **out,
                             PtrError *err)
{
    *out = NULL;
    if (!o->live && !o->tev)
        return PTR_OK;
    PtrLiveView *view = calloc(1, sizeof *view);
    if (!view)
        return ptr_error_set(err, PTR_ERR_NOMEM, "out of memory for the live view");
    PtrResult res = ptr_live_module(&view->module, err);
    PtrLiveOptions options = {
        .http = o->live, .tev = o->tev, .view = apply_view, .view_user = (void *)color,
        .tev_denoised = o->tev && o->denoise,
    };
    if (res == PTR_OK)
        res = view->module->start(&options, &view->session, err);
    if (res != PTR_OK) {
        free(view);
        return res;
    }
    if (o->live)
        fprintf(stderr, "ptr: live view at %s\n", view->module->url(view->session));
    /* The live view works without it: a missing weight file costs the
     * preview only, said once as the broken installation it is; a CPU level
     * without the vector convolution, said once as a fact. */
    PtrError why;
    PtrResult without = o->live || options.tev_denoised
                            ? ptr_live_preview_new(o->cpu_level, hand_denoised, view,
                                                   &view->preview, &why)
                            : PTR_OK;
    if (without != PTR_OK)
        fprintf(stderr, "ptr: %sthe live view has no denoised preview: %s\n",
                without == PTR_ERR_USAGE ? "" : "warning: ", why.message);
    *out = view;
    return PTR_OK;
}

void ptr_live_view_close(PtrLiveView *view)
{
    if (!view)
        return;
    /* Before the session it hands its images to. */
    ptr_live_preview_free(view->preview);
    view->module->stop(view->session);
    free(view->scratch);
    free(view);
}

/* After each pass, on the thread that runs the render, while its threads
 * wait: the film resolved (a read of it, as the final image's), handed
 * over with the progress. */
static void pass_done(void *user, const double *film, size_t pixels, size_t stride,
                      const PtrProgress *p)
{
    PtrLiveView *view = user;
    if (pixels != view->scratch_pixels)
        return;
    ptr_accum_resolve(film, pixels, stride, view->scratch, NULL, NULL);
    double per_sample = p->samples_done ? p->elapsed / p->samples_done : 0;
    view->last = (PtrLiveStatus){
        .samples_done = p->samples_done, .samples_total = p->samples_total,
        .elapsed = p->elapsed,
        .remaining = p->samples_done ? per_sample * (p->samples_total - p->samples_done) : -1,
        .mrays_per_second = p->rays_seconds > 0 ? 1e-6 * (double)p->rays / p->rays_seconds : 0,
        .state = PTR_LIVE_RENDERING,
    };
    uint64_t frame = view->module->frame(view->session, view->scratch, &view->last);
    /* Only while wanted: the copy, and the reading of the film's passes,
     * take place while the render's threads wait. */
    if (view->preview && view->module->denoise_wanted(view->session))
        ptr_live_preview_frame(view->preview, frame, view->scratch, film, pixels, stride);
}

void ptr_live_view_begin(PtrLiveView *view, const char *scene_path, const char *output,
                         const PtrScene *scene, const PtrAccel *accel,
                         const PtrRenderSettings *settings, PtrProgressiveOptions *passes)
{
    if (!view)
        return;
    PtrRegion region = ptr_render_region(settings);
    int width = region.x1 - region.x0, height = region.y1 - region.y0;
    size_t pixels = (size_t)width * (size_t)height;
    if (pixels != view->scratch_pixels) {
        free(view->scratch);
        view->scratch = malloc(pixels * 3 * sizeof *view->scratch);
        view->scratch_pixels = view->scratch ? pixels : 0;
    }
    view->last = (PtrLiveStatus){ .remaining = -1 };
    view->module->begin(view->session, scene_path, output, width, height);
    if (view->preview)
        ptr_live_preview_begin(view->preview, scene, accel, settings, passes->first_sample,
                               passes->samples);
    if (view->scratch) {
        passes->pass_done = pass_done;
        passes->pass_user = view;
    }
}

void ptr_live_view_end(PtrLiveView *view, int ok)
{
    if (!view)
        return;
    if (view->preview)
        ptr_live_preview_end(view->preview);
    view->last.state = ok ? PTR_LIVE_DONE : PTR_LIVE_FAILED;
    view->last.remaining = 0;
    view->module->end(view->session, &view->last);
}
