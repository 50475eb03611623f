/* A closed form for direct lighting: a diffuse ground sphere (albedo 0.5,
 * top at y = 0) lit by one emitter (radius 0.25, radiance 10) 1.5 above it
 * and 3.5 to the side, under a black sky, seen from 10 above the origin
 * looking down through 30 degrees (the emitter out of view). Where the
 * emitter is wholly above the horizon, a ground point shows
 * a L (r/d)^2 cos(theta) (d: distance to the emitter's centre, theta:
 * between the normal and the direction to it). Every pixel of the view
 * qualifies. Used by test_lights (radius 1000) and the stability suite
 * (radius 1e5, ground in double or in float). */
#ifndef PTR_TEST_LIT_GROUND_H
#define PTR_TEST_LIT_GROUND_H

#include "builder.h"
#include "render/camera.h"
#include "render/render.h"
#include "test.h"

enum { LIT_GROUND_SIZE = 32 };

typedef struct LitGroundErrors {
    double worst; /* largest relative error of a pixel */
    double mean;  /* relative error of the image's mean */
} LitGroundErrors;

static inline LitGroundErrors lit_ground_errors(double ground_radius, unsigned build_flags,
                                                const PtrIsectTable *isect,
                                                PtrRenderSettings settings)
{
    const double a = 0.5, L = 10, r = 0.25, big = ground_radius;
    const double emitter[3] = { 3.5, 1.5, 0 }, ground[3] = { 0, -big, 0 };
    PtrScene s;
    ptr_scene_init(&s);
    uint32_t g, l;
    const PtrMaterial diffuse = { .kind = PTR_MATERIAL_DIFFUSE, .albedo = v3_splat((float)a) };
    const PtrMaterial lamp = { .kind = PTR_MATERIAL_DIFFUSE, .emission = v3_splat((float)L) };
    CHECK_INT(ptr_scene_add_material(&s, &diffuse, &g, NULL), PTR_OK);
    CHECK_INT(ptr_scene_add_material(&s, &lamp, &l, NULL), PTR_OK);
    PtrSceneBuilder b;
    ptr_builder_init(&b, &s, NULL);
    CHECK_INT(ptr_builder_add_sphere(&b, ground, big, g, NULL), PTR_OK);
    CHECK_INT(ptr_builder_add_sphere(&b, emitter, r, l, NULL), PTR_OK);
    const double eye[3] = { 0, 10, 0 }, target[3] = { 0, 0, 0 }, up[3] = { 0, 0, -1 };
    const PtrCamera lens = { .vfov_deg = 30, .focus_distance = 10 };
    ptr_builder_set_camera(&b, eye, target, up, &lens);
    CHECK_INT(ptr_builder_finish(&b, build_flags, NULL), PTR_OK);
    s.sky.kind = PTR_SKY_BLACK;

    const int size = LIT_GROUND_SIZE;
    settings.width = settings.height = size;
    float *rgb = malloc((size_t)size * size * 3 * sizeof *rgb);
    PtrError err = { 0 };
    const PtrAccel accel = ptr_accel_brute(isect, &s);
    CHECK_INT(ptr_render(&s, &accel, &settings, rgb, NULL, &err), PTR_OK);

    /* Everything below in the scene's coordinates (relative to s.origin),
     * in double. */
    double gc[3], ec[3];
    for (int k = 0; k < 3; k++) {
        gc[k] = ground[k] - s.origin[k];
        ec[k] = emitter[k] - s.origin[k];
    }
    PtrView view;
    CHECK(ptr_view_init(&view, &s.camera, size, size));
    LitGroundErrors e = { 0, 0 };
    double sum = 0, expected_sum = 0;
    int pixels = 0;
    for (int y = 0; y < size; y++)
        for (int x = 0; x < size; x++) {
            PtrVec3 o, d;
            ptr_view_ray(&view, x, y, 0.5f, 0.5f, 0, 0, &o, &d);
            /* The pixel centre's ground point. */
            const double oc[3] = { o.x - gc[0], o.y - gc[1], o.z - gc[2] };
            const double dd[3] = { d.x, d.y, d.z };
            double bq = 0, cq = 0;
            for (int k = 0; k < 3; k++) {
                bq += oc[k] * dd[k];
                cq += oc[k] * oc[k];
            }
            cq -= big * big;
            double t = -bq - sqrt(bq * bq - cq), dist = 0, rise = 0;
            for (int k = 0; k < 3; k++) {
                double p = oc[k] + t * dd[k]; /* relative to the ground's centre */
                double to = ec[k] - gc[k] - p;
                dist += to * to;
                rise += p / big * to;
            }
            dist = sqrt(dist);
            if (rise <= r * 1.01)
                continue; /* not wholly above the horizon */
            double expected = a * L * (r / dist) * (r / dist) * (rise / dist);
            double value = rgb[3 * (y * size + x)];
            e.worst = fmax(e.worst, fabs(value - expected) / expected);
            sum += value;
            expected_sum += expected;
            pixels++;
        }
    CHECK_INT(pixels, size * size);
    e.mean = fabs(sum - expected_sum) / expected_sum;
    free(rgb);
    ptr_scene_free(&s);
    return e;
}

#endif /* PTR_TEST_LIT_GROUND_H */
