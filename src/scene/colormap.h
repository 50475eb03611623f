/* Colour by a quantity: a per-sphere value through a range onto a colormap's
 * colour, which replaces the sphere's base colour (docs/scenes.md). */
#ifndef PTR_COLORMAP_H
#define PTR_COLORMAP_H

#include "base/result.h"
#include "base/vec.h"
#include "scene/scene.h"

typedef struct PtrColormap {
    const char *name;
    const float (*srgb)[3]; /* 256 entries, sRGB-encoded, low values first */
} PtrColormap;

/* viridis, magma, inferno, plasma, cividis, coolwarm (colormap_tables.c, from
 * scripts/make_colormaps.py); ends with a NULL name. */
extern const PtrColormap ptr_colormaps[];

/* The maps' names, as messages list them. */
#define PTR_COLORMAP_NAMES "viridis, magma, inferno, plasma, cividis or coolwarm"

/* The map of that name, or NULL. */
const PtrColormap *ptr_colormap_find(const char *name);

/* Whether range (--color-range MIN,MAX) is one: both finite, MIN below MAX. */
int ptr_color_range_ok(const double range[2]);

/* IEC 61966-2-1's decoding of an sRGB-encoded channel (0 to 1) to linear
 * light. */
float ptr_srgb_to_linear(float c);

/* The entry for value between lo and hi, as matplotlib picks it: the range
 * cut into 256 equal bins (hi itself in the last), values beyond it clamped
 * to the ends, every value the first entry when lo == hi. */
PtrVec3 ptr_colormap_srgb(const PtrColormap *map, double value, double lo, double hi);

/* That entry decoded from sRGB to linear light: the albedo of a diffuse
 * sphere that, lit by white light of radiance 1, shows the entry through an
 * sRGB view. */
PtrVec3 ptr_colormap_linear(const PtrColormap *map, double value, double lo, double hi);

/* Every sphere with a value (PtrSpheres.value not NaN) gets the colour of its
 * value as its own colour, and a copy of its material whose base colour is
 * white, so the mapped colour replaces the base colour instead of
 * multiplying it; emission, fuzz and ior are kept. Other spheres are left as
 * they are. Fails only for memory (PTR_ERR_NOMEM, said in err, which may
 * be NULL). */
PtrResult ptr_scene_color_by_value(PtrScene *scene, const PtrColormap *map, double lo,
                                   double hi, PtrError *err);

/* What ptr_scene_color_by_range mapped: the spheres with a value, the range
 * of their values (lo above hi when none has one), and the range mapped
 * onto the colormap's ends through map. */
typedef struct PtrColorMapping {
    const PtrColormap *map;
    size_t valued;
    double lo, hi;
    double from, to;
} PtrColorMapping;

/* --color-by of a scene with values (PtrSpheres.value): maps them through
 * map (NULL: viridis, the first) from range[0] to range[1], or, range NULL,
 * over their own range, by ptr_scene_color_by_value; says in *mapping what
 * it mapped. The command line and the library's loads colour through this
 * alone. Fails only for memory. */
PtrResult ptr_scene_color_by_range(PtrScene *scene, const PtrColormap *map, const double *range,
                                   PtrColorMapping *mapping, PtrError *err);

#endif /* PTR_COLORMAP_H */
