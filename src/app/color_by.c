#include "app/color_by.h"

#include <stdio.h>
#include <stdlib.h>

#include "api/output.h"
#include "scene/colormap.h"

enum { BAR_WIDTH = 512, BAR_HEIGHT = 32 }; /* two columns an entry of 256 */

/* The map from lo (left) to hi (right), each column the colour its centre's
 * value gets, written as a render is, through the same view, at its
 * format's default depth (a key needs no more). */
static PtrResult write_bar(const PtrOptions *o, const PtrColormap *map, const char *scene_path,
                           const PtrColor *color, PtrError *err)
{
    PtrResult usable = ptr_output_check(o->images, o->color_bar, PTR_DEPTH_DEFAULT, 0, 0, err);
    if (usable != PTR_OK)
        return usable;
    float *rgb = malloc((size_t)BAR_WIDTH * BAR_HEIGHT * 3 * sizeof *rgb);
    if (!rgb)
        return ptr_error_set(err, PTR_ERR_NOMEM, "%s: out of memory", o->color_bar);
    for (int x = 0; x < BAR_WIDTH; x++) {
        PtrVec3 c = ptr_colormap_linear(map, (x + 0.5) / BAR_WIDTH, 0.0, 1.0);
        for (int y = 0; y < BAR_HEIGHT; y++) {
            float *p = &rgb[3 * ((size_t)y * BAR_WIDTH + (size_t)x)];
            p[0] = c.x;
            p[1] = c.y;
            p[2] = c.z;
        }
    }
    const PtrImageLayout layout = { BAR_WIDTH, BAR_HEIGHT, 0, 0, BAR_WIDTH, BAR_HEIGHT };
    PtrOutputInfo info = {
        .scene_path = scene_path, .kernel = "", .accel = "", .sampler = "",
        .output = ptr_options_output(o, color),
    };
    info.output.depth = PTR_DEPTH_DEFAULT;
    PtrResult res = ptr_output_write(o->images, o->color_bar, &layout, rgb, &info, err);
    free(rgb);
    return res;
}

PtrResult ptr_color_by_apply(const PtrOptions *o, const char *scene_path, PtrScene *scene,
                             const PtrColor *color, PtrError *err)
{
    if (!o->color_by)
        return PTR_OK;
    /* Only a structure's colour scheme (chain, entity, ...) gets here
     * without values: the importer coloured the spheres, and no colormap
     * takes part. */
    if (!scene->spheres.value)
        return o->colormap || o->has_color_range || o->color_bar
                   ? ptr_error_set(err, PTR_ERR_USAGE,
                                   "%s: --color-by %s is a colour scheme, not a quantity: it "
                                   "takes no --colormap, --color-range or --color-bar",
                                   scene_path, o->color_by)
                   : PTR_OK;
    PtrColorMapping mapping;
    PtrError problem;
    PtrResult res = ptr_scene_color_by_range(scene, o->colormap,
                                             o->has_color_range ? o->color_range : NULL,
                                             &mapping, &problem);
    if (res != PTR_OK)
        return ptr_error_set(err, res, "%s: --color-by: %s", scene_path, problem.message);
    if (!o->quiet)
        fprintf(stderr, "ptr: %s: --color-by %s: %zu spheres, values %.9g to %.9g, mapped from "
                        "%.9g to %.9g through %s\n", scene_path, o->color_by, mapping.valued,
                mapping.lo, mapping.hi, mapping.from, mapping.to, mapping.map->name);
    return o->color_bar && color ? write_bar(o, mapping.map, scene_path, color, err) : PTR_OK;
}
