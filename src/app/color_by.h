/* --color-by: a per-sphere quantity through a range onto a colormap, and the
 * colour bar that says which colour is which value. */
#ifndef PTR_COLOR_BY_H
#define PTR_COLOR_BY_H

#include "app/cli_options.h"
#include "base/result.h"
#include "color/color.h"
#include "scene/scene.h"

/* With --color-by: maps the imported scene's values through --colormap and
 * --color-range (default: the values' range) as the library's loads do
 * (ptr_scene_color_by_range), says on stderr (unless --quiet) which range
 * it mapped, and, given a colour config (a render, not --dump-scene),
 * writes --color-bar through it, which the library does not. Does nothing
 * without --color-by. */
PtrResult ptr_color_by_apply(const PtrOptions *o, const char *scene_path, PtrScene *scene,
                             const PtrColor *color, PtrError *err);

#endif /* PTR_COLOR_BY_H */
