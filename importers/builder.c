#include "builder.h"

#include <float.h>
#include <math.h>
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
    builder->spheres = NULL;
    builder->materials = NULL;
    builder->count = builder->capacity = 0;
}

PtrResult ptr_builder_add_sphere(PtrSceneBuilder *b, const double centre[3], double radius,
                                 uint32_t material)
{
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
        b->capacity = capacity;
    }
    double *s = &b->spheres[4 * b->count];
    s[0] = centre[0];
    s[1] = centre[1];
    s[2] = centre[2];
    s[3] = radius;
    b->materials[b->count++] = material;
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
        .vfov_deg = (float)c->vfov_deg, .aperture = (float)c->aperture,
        .focus_distance = (float)(c->focus_distance > 0 ? c->focus_distance : sqrt(d2)),
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

PtrResult ptr_builder_finish(PtrSceneBuilder *b, int recentre)
{
    PtrScene *scene = b->scene;
    PtrResult res = PTR_OK;
    if (b->override)
        use_override(b);
    else if (!b->has_camera)
        frame_spheres(b);
    const double zero[3] = { 0, 0, 0 };
    const double *origin = recentre ? b->eye : zero;
    memcpy(scene->origin, origin, sizeof scene->origin);

    for (size_t i = 0; i < b->count && res == PTR_OK; i++) {
        PtrVec3 c = relative(&b->spheres[4 * i], origin);
        float r = (float)b->spheres[4 * i + 3];
        if (!isfinite(c.x) || !isfinite(c.y) || !isfinite(c.z) || !(r > 0.0f) || !isfinite(r))
            res = PTR_ERR_SCENE_INVALID;
        else
            res = ptr_scene_add_sphere(scene, c, r, b->materials[i]);
    }
    scene->camera = b->lens;
    scene->camera.lookfrom = relative(b->eye, origin);
    scene->camera.lookat = relative(b->target, origin);
    scene->camera.up = relative(b->up, zero);
    ptr_builder_free(b);
    return res;
}
