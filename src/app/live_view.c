#include "app/live_view.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "app/live_preview.h"
#include "live/live.h"
#include "render/film.h"

static const PtrLiveModule *module;
static PtrLiveSession *session;
static PtrLivePreview *preview; /* NULL: no denoised preview (no weights) */
static float *scratch; /* the resolved film of the render under way */
static size_t scratch_pixels;
static PtrLiveStatus last;

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
    (void)user;
    module->denoised(session, frame, rgb);
}

PtrResult ptr_live_view_open(const PtrOptions *o, const PtrColor *color, PtrError *err)
{
    if (!o->live && !o->tev)
        return PTR_OK;
    PtrResult res = ptr_live_module(&module, err);
    if (res != PTR_OK)
        return res;
    PtrLiveOptions options = {
        .http = o->live, .tev = o->tev, .view = apply_view, .view_user = (void *)color,
        .tev_denoised = o->tev && o->denoise,
    };
    res = module->start(&options, &session, err);
    if (res != PTR_OK)
        return res;
    if (o->live)
        fprintf(stderr, "ptr: live view at %s\n", module->url(session));
    /* The live view works without it: a missing weight file costs the
     * preview only, said once as the broken installation it is; a CPU level
     * without the vector convolution, said once as a fact. */
    PtrError why;
    PtrResult without = o->live || options.tev_denoised
                            ? ptr_live_preview_new(o->cpu_level, hand_denoised, NULL,
                                                   &preview, &why)
                            : PTR_OK;
    if (without != PTR_OK)
        fprintf(stderr, "ptr: %sthe live view has no denoised preview: %s\n",
                without == PTR_ERR_USAGE ? "" : "warning: ", why.message);
    return PTR_OK;
}

void ptr_live_view_close(void)
{
    /* Before the session it hands its images to. */
    ptr_live_preview_free(preview);
    preview = NULL;
    if (session)
        module->stop(session);
    session = NULL;
    free(scratch);
    scratch = NULL;
    scratch_pixels = 0;
}

/* After each pass, on the thread that runs the render, while its threads
 * wait: the film resolved (a read of it, as the final image's), handed
 * over with the progress. */
static void pass_done(void *user, const double *film, size_t pixels, size_t stride,
                      const PtrProgress *p)
{
    (void)user;
    if (pixels != scratch_pixels)
        return;
    ptr_accum_resolve(film, pixels, stride, scratch, NULL, NULL);
    double per_sample = p->samples_done ? p->elapsed / p->samples_done : 0;
    last = (PtrLiveStatus){
        .samples_done = p->samples_done, .samples_total = p->samples_total,
        .elapsed = p->elapsed,
        .remaining = p->samples_done ? per_sample * (p->samples_total - p->samples_done) : -1,
        .mrays_per_second = p->rays_seconds > 0 ? 1e-6 * (double)p->rays / p->rays_seconds : 0,
        .state = PTR_LIVE_RENDERING,
    };
    uint64_t frame = module->frame(session, scratch, &last);
    /* Only while wanted: the copy, and the reading of the film's passes,
     * take place while the render's threads wait. */
    if (preview && module->denoise_wanted(session))
        ptr_live_preview_frame(preview, frame, scratch, film, pixels, stride);
}

void ptr_live_view_begin(const char *scene_path, const char *output, const PtrScene *scene,
                         const PtrAccel *accel, const PtrRenderSettings *settings,
                         PtrProgressiveOptions *passes)
{
    if (!session)
        return;
    PtrRegion region = ptr_render_region(settings);
    int width = region.x1 - region.x0, height = region.y1 - region.y0;
    size_t pixels = (size_t)width * (size_t)height;
    if (pixels != scratch_pixels) {
        free(scratch);
        scratch = malloc(pixels * 3 * sizeof *scratch);
        scratch_pixels = scratch ? pixels : 0;
    }
    last = (PtrLiveStatus){ .remaining = -1 };
    module->begin(session, scene_path, output, width, height);
    if (preview)
        ptr_live_preview_begin(preview, scene, accel, settings, passes->first_sample,
                               passes->samples);
    if (scratch) {
        passes->pass_done = pass_done;
        passes->pass_user = NULL;
    }
}

void ptr_live_view_end(int ok)
{
    if (!session)
        return;
    if (preview)
        ptr_live_preview_end(preview);
    last.state = ok ? PTR_LIVE_DONE : PTR_LIVE_FAILED;
    last.remaining = 0;
    module->end(session, &last);
}
