/* The live view of --live and --tev, for the whole process: one server
 * that follows every render (each scene of a batch, each re-render of
 * --watch). Without either option nothing here loads anything. */
#ifndef PTR_LIVE_VIEW_H
#define PTR_LIVE_VIEW_H

#include <stddef.h>

#include "app/cli_options.h"
#include "color/color.h"
#include "render/progressive.h"

/* Loads the live module and starts the server and tev's sender, printing
 * the page's address on stderr; PTR_OK at once without --live or --tev.
 * color gives the view the page shows; it must outlive the session. */
PtrResult ptr_live_view_open(const PtrOptions *options, const PtrColor *color, PtrError *err);
/* Lets open pages fetch the last image, then stops. */
void ptr_live_view_close(void);

/* A render of settings' region starts: sets passes->pass_done so that each
 * pass reaches the view (nothing when there is no view). scene and accel
 * (from which the denoised preview may render passes) must stay until
 * ptr_live_view_end. */
void ptr_live_view_begin(const char *scene_path, const char *output, const PtrScene *scene,
                         const PtrAccel *accel, const PtrRenderSettings *settings,
                         PtrProgressiveOptions *passes);
/* The render ended, ok or not: nothing reads its scene any more. */
void ptr_live_view_end(int ok);

#endif /* PTR_LIVE_VIEW_H */
