/* The live view of --live and --tev: one server that follows every render
 * of the run that opens it (each scene of a batch, each re-render of
 * --watch). Without either option nothing here loads anything. */
#ifndef PTR_LIVE_VIEW_H
#define PTR_LIVE_VIEW_H

#include <stddef.h>

#include "app/cli_options.h"
#include "color/color.h"
#include "render/progressive.h"

/* Loads the live module and starts the server and tev's sender, printing
 * the page's address on stderr, into *out (for ptr_live_view_close); PTR_OK
 * and *out NULL without --live or --tev. color gives the view the page
 * shows; it must outlive the view. */
PtrResult ptr_live_view_open(const PtrOptions *options, const PtrColor *color, PtrLiveView **out,
                             PtrError *err);
/* Lets open pages fetch the last image, then stops and frees the view.
 * Takes NULL. */
void ptr_live_view_close(PtrLiveView *view);

/* A render of settings' region starts: sets passes->pass_done so that each
 * pass reaches the view (nothing when view is NULL). scene and accel (from
 * which the denoised preview may render passes) must stay until
 * ptr_live_view_end. */
void ptr_live_view_begin(PtrLiveView *view, const char *scene_path, const char *output,
                         const PtrScene *scene, const PtrAccel *accel,
                         const PtrRenderSettings *settings, PtrProgressiveOptions *passes);
/* The render ended, ok or not: nothing reads its scene any more. Takes
 * NULL. */
void ptr_live_view_end(PtrLiveView *view, int ok);

#endif /* PTR_LIVE_VIEW_H */
