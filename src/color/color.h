/* Colour management through OpenColorIO, behind a C interface: which config,
 * which display, view and look, and the transform from the renderer's
 * scene-linear Rec.709 to what a display shows. */
#ifndef PTR_COLOR_H
#define PTR_COLOR_H

#include <stddef.h>
#include <stdio.h>

#include "base/result.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct PtrColor PtrColor;

/* Loads a config into *out (for ptr_color_close): the file at path if given,
 * else the one $OCIO names, else ptr's embedded one. A config that cannot be
 * loaded, fails validation or has no scene_linear role is an error
 * (PTR_ERR_COLOR, or PTR_ERR_NOMEM, with a line naming the file): never a
 * silent fallback to another config. */
PtrResult ptr_color_open(const char *path, PtrColor **out, PtrError *err);
void ptr_color_close(PtrColor *color);

/* Where the config came from: its path, or "embedded". */
const char *ptr_color_source(const PtrColor *color);

/* Chooses the display and view (NULL: the config's defaults), an optional
 * look, and an exposure in stops applied in scene-linear before the view.
 * Returns PTR_OK; PTR_ERR_USAGE for an unknown name, with err listing the
 * valid ones; PTR_ERR_COLOR if OpenColorIO fails, with err saying why. */
PtrResult ptr_color_select(PtrColor *color, const char *display, const char *view,
                           const char *look, float exposure_stops, PtrError *err);

const char *ptr_color_display(const PtrColor *color);
const char *ptr_color_view(const PtrColor *color);
const char *ptr_color_look(const PtrColor *color); /* "" for none */
/* The colour space a display-referred image is in, for file metadata. */
const char *ptr_color_view_space(const PtrColor *color);

/* Transforms RGB pixels in place from scene-linear to the selected view.
 * Returns PTR_OK, or the failure, with err filled. */
PtrResult ptr_color_apply(const PtrColor *color, float *rgb, size_t pixels, PtrError *err);

/* Prints the displays with their views, and the looks. */
PtrResult ptr_color_list(const PtrColor *color, FILE *out, PtrError *err);

/* ptr's embedded config, as text. */
extern const char ptr_embedded_ocio_config[];

#ifdef __cplusplus
}
#endif

#endif /* PTR_COLOR_H */
