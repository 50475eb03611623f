#include "scene/colormap.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

const PtrColormap *ptr_colormap_find(const char *name)
{
    for (const PtrColormap *map = ptr_colormaps; map->name; map++)
        if (!strcmp(map->name, name))
            return map;
    return NULL;
}

int ptr_color_range_ok(const double range[2])
{
    return isfinite(range[0]) && isfinite(range[1]) && range[0] < range[1];
}

PtrVec3 ptr_colormap_srgb(const PtrColormap *map, double value, double lo, double hi)
{
    double t = hi > lo ? (value - lo) / (hi - lo) : 0.0;
    t = t > 0.0 ? t : 0.0; /* NaN too */
    int index = t >= 1.0 ? 255 : (int)(t * 256.0);
    const float *c = map->srgb[index];
    return v3(c[0], c[1], c[2]);
}

float ptr_srgb_to_linear(float c)
{
    /* In double, rounded once at the end: the float result nearest the
     * standard's, which powf's own rounding and the float constants miss by
     * a last bit for some inputs. */
    return (float)(c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4));
}

PtrVec3 ptr_colormap_linear(const PtrColormap *map, double value, double lo, double hi)
{
    PtrVec3 c = ptr_colormap_srgb(map, value, lo, hi);
    return v3(ptr_srgb_to_linear(c.x), ptr_srgb_to_linear(c.y), ptr_srgb_to_linear(c.z));
}

PtrResult ptr_scene_color_by_value(PtrScene *scene, const PtrColormap *map, double lo,
                                   double hi, PtrError *err)
{
    PtrSpheres *s = &scene->spheres;
    const size_t materials = scene->material_count;
    if (!s->value)
        return PTR_OK;
    /* The white copy of each material, made when a sphere first needs it. */
    uint32_t *white = malloc((materials ? materials : 1) * sizeof *white);
    if (!white)
        return ptr_error_set(err, PTR_ERR_NOMEM, "out of memory for %zu materials", materials);
    for (size_t m = 0; m < materials; m++)
        white[m] = UINT32_MAX;
    PtrResult res = PTR_OK;
    for (size_t i = 0; i < s->count && res == PTR_OK; i++) {
        const float value = s->value[ptr_sphere_id(s, i)]; /* in file order: see PtrSpheres */
        if (isnan(value))
            continue;
        uint32_t m = ptr_sphere_material(s, i);
        if (white[m] == UINT32_MAX) {
            PtrMaterial copy = scene->materials[m];
            copy.albedo = v3_splat(1.0f);
            res = ptr_scene_add_material(scene, &copy, &white[m], err);
        }
        if (res == PTR_OK) {
            ptr_sphere_set_material(s, i, white[m]);
            res = ptr_scene_set_sphere_color(scene, i,
                                             ptr_colormap_linear(map, value, lo, hi), err);
        }
    }
    free(white);
    return res;
}

PtrResult ptr_scene_color_by_range(PtrScene *scene, const PtrColormap *map, const double *range,
                                   PtrColorMapping *mapping, PtrError *err)
{
    const PtrSpheres *s = &scene->spheres;
    PtrColorMapping m = { .map = map ? map : &ptr_colormaps[0], .lo = INFINITY, .hi = -INFINITY };
    for (size_t i = 0; s->value && i < s->count; i++) {
        if (isnan(s->value[i]))
            continue;
        m.lo = fmin(m.lo, s->value[i]);
        m.hi = fmax(m.hi, s->value[i]);
        m.valued++;
    }
    m.from = range ? range[0] : m.lo;
    m.to = range ? range[1] : m.hi;
    *mapping = m;
    return ptr_scene_color_by_value(scene, m.map, m.from, m.to, err);
}
