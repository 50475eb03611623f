/* The live view's denoised preview: the frames a page (or tev) wants
 * denoised are handed over after their pass, and a thread of its own, at a
 * low priority and within a share of the cores, denoises the newest one
 * with the small network on one core, dropping those that arrive
 * meanwhile. The render copies a frame and takes a lock for a swap of
 * pointers, nothing more.
 *
 * The denoiser needs the albedo and normal passes. A film that records them
 * (--passes, --denoise) gives its own; otherwise, the first time a frame of
 * a render is to be denoised, the preview renders them itself, once, from a
 * few samples of the same scene: recording them in the render's film would
 * cost every render with --live 7 to 13% of its instructions (README, Live
 * view). */
#ifndef PTR_LIVE_PREVIEW_H
#define PTR_LIVE_PREVIEW_H

#include <stddef.h>
#include <stdint.h>

#include "base/cpu.h"
#include "render/render.h"

typedef struct PtrLivePreview PtrLivePreview;

/* Called on the preview's thread with the denoised image (RGB, the frame's
 * size) of the frame numbered frame. */
typedef void (*PtrLivePreviewDone)(void *user, uint64_t frame, const float *rgb);

/* Loads the small network's weights for this CPU level and starts the
 * thread: PTR_ERR_USAGE at a level whose convolution is the C reference,
 * PTR_ERR_INSTALL (a missing weight file), PTR_ERR_NOMEM, PTR_ERR_INTERNAL. */
PtrResult ptr_live_preview_new(PtrCpuLevel level, PtrLivePreviewDone done, void *user,
                               PtrLivePreview **out, PtrError *err);
/* Denoises the frame handed over last if it is not yet (unless a signal
 * asked the process to stop), then stops the thread. */
void ptr_live_preview_free(PtrLivePreview *preview);

/* A render starts: what its passes are rendered from if its film has none.
 * scene and accel must stay until ptr_live_preview_end. */
void ptr_live_preview_begin(PtrLivePreview *preview, const PtrScene *scene,
                            const PtrAccel *accel, const PtrRenderSettings *settings,
                            uint32_t first_sample, uint32_t samples);
/* The frame numbered frame, to be denoised: its colour (rgb, resolved from
 * film) and the film of the render (pixels pixels of stride doubles: its
 * passes are read if it has them). Copied, never kept. */
void ptr_live_preview_frame(PtrLivePreview *preview, uint64_t frame, const float *rgb,
                            const double *film, size_t pixels, size_t stride);
/* The render ended: returns once the preview no longer reads its scene. */
void ptr_live_preview_end(PtrLivePreview *preview);

#endif /* PTR_LIVE_PREVIEW_H */
