#include "builder.h"

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

void ptr_builder_init(PtrSceneBuilder *builder, PtrScene *scene, const PtrCameraSpec *override)
{
    memset(builder, 0, sizeof *builder);
    builder->scene = scene;
    builder->override = override;
}

void ptr_builder_free(PtrSceneBuilder *builder)
{
    free(builder->spheres);
    free(builder->materials);
    free(builder->colors);
    free(builder->values);
    builder->spheres = NULL;
    builder->materials = NULL;
    builder->colors = NULL;
    builder->values = NULL;
    builder->count = builder->capacity = 0;
}

/* The optional per-sphere arrays (width floats a sphere, and the value of a
 * sphere that has none): they exist from the first sphere that has one. */
enum { OPTIONAL_COLORS, OPTIONAL_VALUES };
static const struct {
    size_t offset;
    int width;
    float none;
} optional_arrays[] = {
    [OPTIONAL_COLORS] = { offsetof(PtrSceneBuilder, colors), 3, 1.0f }, /* white */
    [OPTIONAL_VALUES] = { offsetof(PtrSceneBuilder, values), 1, NAN },
};

static float **optional_array(PtrSceneBuilder *b, size_t k)
{
    return (float **)((char *)b + optional_arrays[k].offset);
}

/* Entries from .. to - 1 of optional array k get its value for none. */
static void fill_none(PtrSceneBuilder *b, size_t k, size_t from, size_t to)
{
    const int width = optional_arrays[k].width;
    for (size_t i = from * (size_t)width; i < to * (size_t)width; i++)
        (*optional_array(b, k))[i] = optional_arrays[k].none;
}

PtrResult ptr_builder_add_sphere(PtrSceneBuilder *b, const double centre[3], double radius,
                                 uint32_t material)
{
    const size_t optionals = sizeof optional_arrays / sizeof optional_arrays[0];
    if (b->count == b->capacity) {
        size_t capacity = b->capacity ? 2 * b->capacity : 64;
        double *spheres = realloc(b->spheres, capacity * 4 * sizeof *spheres);
        if (!spheres)
            return PTR_ERR_NOMEM;
        b->spheres = spheres;
        uint32_t *materials = realloc(b->materials, capacity * sizeof *materials);
        if (!materials)
            return PTR_ERR_NOMEM;
        b->materials = materials;
        for (size_t k = 0; k < optionals; k++) {
            float **array = optional_array(b, k);
            if (!*array)
                continue;
            float *grown = realloc(*array, capacity * (size_t)optional_arrays[k].width *
                                               sizeof *grown);
            if (!grown)
                return PTR_ERR_NOMEM;
            *array = grown;
        }
        b->capacity = capacity;
    }
    for (size_t k = 0; k < optionals; k++)
        if (*optional_array(b, k))
            fill_none(b, k, b->count, b->count + 1);
    double *s = &b->spheres[4 * b->count];
    s[0] = centre[0];
    s[1] = centre[1];
    s[2] = centre[2];
    s[3] = radius;
    b->materials[b->count++] = material;
    return PTR_OK;
}

/* Optional array k's entry for the sphere added last, the array created if
 * it is the first. NULL if memory runs out. */
static float *last_entry(PtrSceneBuilder *b, size_t k)
{
    float **array = optional_array(b, k);
    const int width = optional_arrays[k].width;
    if (!*array) {
        *array = malloc(b->capacity * (size_t)width * sizeof **array);
        if (!*array)
            return NULL;
        fill_none(b, k, 0, b->capacity);
    }
    return &(*array)[(b->count - 1) * (size_t)width];
}

PtrResult ptr_builder_set_color(PtrSceneBuilder *b, const double rgb[3])
{
    float *entry = last_entry(b, OPTIONAL_COLORS);
    if (!entry)
        return PTR_ERR_NOMEM;
    for (int k = 0; k < 3; k++)
        entry[k] = (float)rgb[k];
    return PTR_OK;
}

PtrResult ptr_builder_set_value(PtrSceneBuilder *b, double value)
{
    float *entry = last_entry(b, OPTIONAL_VALUES);
    if (!entry)
        return PTR_ERR_NOMEM;
    *entry = (float)value;
    return PTR_OK;
}

static void place_camera(PtrSceneBuilder *b, const double eye[3], const double target[3],
                         const double up[3], const PtrCamera *lens)
{
    memcpy(b->eye, eye, sizeof b->eye);
    memcpy(b->target, target, sizeof b->target);
    memcpy(b->up, up, sizeof b->up);
    b->lens = *lens;
    b->has_camera = 1;
}

void ptr_builder_set_camera(PtrSceneBuilder *b, const double eye[3], const double target[3],
                            const double up[3], const PtrCamera *lens)
{
    if (!b->override)
        place_camera(b, eye, target, up, lens);
}

static void use_override(PtrSceneBuilder *b)
{
    const PtrCameraSpec *c = b->override;
    double d2 = 0;
    for (int k = 0; k < 3; k++)
        d2 += (c->lookat[k] - c->lookfrom[k]) * (c->lookat[k] - c->lookfrom[k]);
    const PtrCamera lens = {
        .projection = c->ortho_height > 0 ? PTR_PROJECTION_ORTHOGRAPHIC
                                          : PTR_PROJECTION_PERSPECTIVE,
        .vfov_deg = (float)c->vfov_deg, .aperture = (float)c->aperture,
        .focus_distance = (float)(c->focus_distance > 0 ? c->focus_distance : sqrt(d2)),
        .ymag = (float)(0.5 * c->ortho_height),
    };
    place_camera(b, c->lookfrom, c->lookat, c->up, &lens);
}

/* Far enough back along +Z that the bounding sphere of all spheres' box fits
 * a 40 degree vertical field of view (and so the wider horizontal one). */
static void frame_spheres(PtrSceneBuilder *b)
{
    double lo[3] = { 0, 0, 0 }, hi[3] = { 0, 0, 0 };
    for (size_t i = 0; i < b->count; i++) {
        const double *s = &b->spheres[4 * i];
        for (int k = 0; k < 3; k++) {
            lo[k] = i ? fmin(lo[k], s[k] - s[3]) : s[k] - s[3];
            hi[k] = i ? fmax(hi[k], s[k] + s[3]) : s[k] + s[3];
        }
    }
    const double vfov_deg = 40.0;
    double centre[3], diagonal2 = 0;
    for (int k = 0; k < 3; k++) {
        centre[k] = 0.5 * (lo[k] + hi[k]);
        diagonal2 += (hi[k] - lo[k]) * (hi[k] - lo[k]);
    }
    double bound = diagonal2 > 0 ? 0.5 * sqrt(diagonal2) : 1.0;
    double distance = bound / sin(0.5 * vfov_deg * 3.14159265358979323846 / 180.0);
    const double eye[3] = { centre[0], centre[1], centre[2] + distance };
    const double up[3] = { 0, 1, 0 };
    const PtrCamera lens = { .vfov_deg = (float)vfov_deg, .focus_distance = (float)distance };
    place_camera(b, eye, centre, up, &lens);
}

static PtrVec3 relative(const double p[3], const double origin[3])
{
    return v3((float)(p[0] - origin[0]), (float)(p[1] - origin[1]), (float)(p[2] - origin[2]));
}

/* Which spheres are huge (see accel/huge.h): those whose radius is more than
 * HUGE_RATIO times the extent E of the region the rays live in, taken as the
 * box around the camera and every sphere of a radius within SMALL_RATIO of
 * the smallest. In float, rays leave a sphere of radius r lifted by about
 * 2^-20 r; below 256 E that is under 2^-12 E, less than a pixel of a 4K
 * image of the whole region, and the double test would only cost time (a
 * quarter of the rays per second on a four-sphere scene). A radius-1e5
 * ground under a scene a few units (or a room 100) across is huge; the
 * radius-100 and radius-1000 grounds of seed.gltf and final.gltf are not;
 * a cloud of like spheres has none. At most PTR_HUGE_MAX, the largest first
 * (every ray tests them all). Marks them in huge[] (all zero on entry) and
 * returns how many. */
#define HUGE_RATIO 256.0
#define SMALL_RATIO 16.0

static size_t choose_huge(const PtrSceneBuilder *b, const double eye[3], unsigned char *huge)
{
    double smallest = INFINITY;
    for (size_t i = 0; i < b->count; i++)
        smallest = fmin(smallest, b->spheres[4 * i + 3]);
    double lo[3], hi[3];
    memcpy(lo, eye, sizeof lo);
    memcpy(hi, eye, sizeof hi);
    for (size_t i = 0; i < b->count; i++) {
        const double *s = &b->spheres[4 * i];
        if (s[3] > SMALL_RATIO * smallest)
            continue;
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], s[k] - s[3]);
            hi[k] = fmax(hi[k], s[k] + s[3]);
        }
    }
    double extent = 0;
    for (int k = 0; k < 3; k++)
        extent = fmax(extent, hi[k] - lo[k]);
    /* The largest candidates, largest first (the earliest on equal radii). */
    size_t top[PTR_HUGE_MAX], count = 0;
    for (size_t i = 0; i < b->count; i++) {
        double r = b->spheres[4 * i + 3];
        if (!(r > HUGE_RATIO * extent))
            continue;
        size_t at = count < PTR_HUGE_MAX ? count++ : PTR_HUGE_MAX;
        for (; at > 0 && b->spheres[4 * top[at - 1] + 3] < r; at--)
            if (at < PTR_HUGE_MAX)
                top[at] = top[at - 1];
        if (at < PTR_HUGE_MAX)
            top[at] = i;
    }
    for (size_t k = 0; k < count; k++)
        huge[top[k]] = 1;
    return count;
}

/* Adds sphere i of the builder (already relative to the scene's origin). */
static PtrResult add_sphere(PtrSceneBuilder *b, size_t i)
{
    const double *s = &b->spheres[4 * i];
    PtrVec3 c = v3((float)s[0], (float)s[1], (float)s[2]);
    float r = (float)s[3];
    if (!isfinite(c.x) || !isfinite(c.y) || !isfinite(c.z) || !(r > 0.0f) || !isfinite(r))
        return PTR_ERR_SCENE_INVALID;
    PtrScene *scene = b->scene;
    PtrResult res = ptr_scene_add_sphere(scene, c, r, b->materials[i]);
    size_t added = scene->spheres.count - 1;
    if (res == PTR_OK)
        scene->spheres.id[added] = (uint32_t)i;
    if (res == PTR_OK && b->colors) {
        const float *rgb = &b->colors[3 * i];
        res = ptr_scene_set_sphere_color(scene, added, v3(rgb[0], rgb[1], rgb[2]));
    }
    if (res == PTR_OK && b->values)
        res = ptr_scene_set_sphere_value(scene, added, b->values[i]);
    return res;
}

/* The spheres in file order, the huge ones last (their ids keep the file's
 * order; see PtrSpheres.id), with the huge ones in double as well. */
static PtrResult add_spheres(PtrSceneBuilder *b, const double origin[3], int huge_in_double)
{
    PtrScene *scene = b->scene;
    unsigned char *huge = malloc(b->count ? b->count : 1);
    if (!huge)
        return PTR_ERR_NOMEM;
    const double eye[3] = { b->eye[0] - origin[0], b->eye[1] - origin[1], b->eye[2] - origin[2] };
    for (size_t i = 0; i < b->count; i++)
        for (int k = 0; k < 3; k++)
            b->spheres[4 * i + k] -= origin[k];
    memset(huge, 0, b->count);
    size_t huge_count = huge_in_double ? choose_huge(b, eye, huge) : 0;
    PtrResult res = PTR_OK;
    for (size_t i = 0; i < b->count && res == PTR_OK; i++)
        if (!huge[i])
            res = add_sphere(b, i);
    if (res == PTR_OK && huge_count) {
        scene->huge.centre_radius = malloc(huge_count * 4 * sizeof(double));
        if (!scene->huge.centre_radius)
            res = PTR_ERR_NOMEM;
    }
    for (size_t i = 0; i < b->count && res == PTR_OK; i++) {
        if (!huge[i])
            continue;
        res = add_sphere(b, i);
        memcpy(&scene->huge.centre_radius[4 * scene->huge.count++], &b->spheres[4 * i],
               4 * sizeof(double));
    }
    free(huge);
    return res;
}

PtrResult ptr_builder_finish(PtrSceneBuilder *b, unsigned flags)
{
    PtrScene *scene = b->scene;
    PtrResult res = PTR_OK;
    if (b->override)
        use_override(b);
    else if (!b->has_camera)
        frame_spheres(b);
    const double zero[3] = { 0, 0, 0 };
    const double *origin = flags & PTR_BUILD_RECENTRE ? b->eye : zero;
    memcpy(scene->origin, origin, sizeof scene->origin);

    res = add_spheres(b, origin, flags & PTR_BUILD_HUGE_IN_DOUBLE);
    scene->camera = b->lens;
    scene->camera.lookfrom = relative(b->eye, origin);
    scene->camera.lookat = relative(b->target, origin);
    scene->camera.up = relative(b->up, zero);
    ptr_builder_free(b);
    return res;
}
