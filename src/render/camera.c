#include "render/camera.h"

#include <math.h>

/* Whether the projection's own values can make an image. */
static int projection_valid(const PtrCamera *c)
{
    if (c->projection == PTR_PROJECTION_ORTHOGRAPHIC)
        return c->ymag > 0.0f && isfinite(c->ymag) && c->znear >= 0.0f && isfinite(c->znear);
    return c->vfov_deg > 0.0f && c->vfov_deg < 180.0f && c->focus_distance > 0.0f &&
           isfinite(c->focus_distance);
}

int ptr_view_init(PtrView *view, const PtrCamera *camera, int width, int height)
{
    PtrVec3 back = v3_sub(camera->lookfrom, camera->lookat);
    PtrVec3 right = v3_cross(camera->up, back);
    float back_len = v3_length(back), right_len = v3_length(right);
    if (!(back_len > 0.0f) || !(right_len > 1e-6f * back_len * v3_length(camera->up)) ||
        !projection_valid(camera) || !(camera->aperture >= 0.0f) ||
        !isfinite(camera->aperture) || width <= 0 || height <= 0)
        return 0;

    PtrVec3 w = v3_scale(back, 1.0f / back_len);
    PtrVec3 u = v3_scale(right, 1.0f / right_len);
    PtrVec3 v = v3_cross(w, u);

    /* The pixels lie on a plane across the view: the focus plane of a lens,
     * where a pixel's rays meet; the near plane of parallel rays, where they
     * start. */
    int ortho = camera->projection == PTR_PROJECTION_ORTHOGRAPHIC;
    float plane = ortho ? camera->znear : camera->focus_distance;
    float half_height = ortho ? camera->ymag
                              : tanf(0.5f * camera->vfov_deg * PTR_PI / 180.0f) *
                                    camera->focus_distance;
    float half_width = half_height * (float)width / (float)height;
    PtrVec3 du = v3_scale(u, 2.0f * half_width / (float)width);
    PtrVec3 dv = v3_scale(v, -2.0f * half_height / (float)height);
    PtrVec3 top_left = v3_add(v3_sub(camera->lookfrom, v3_scale(w, plane)),
                              v3_sub(v3_scale(v, half_height), v3_scale(u, half_width)));
    /* Parallel rays have no lens to blur them: the aperture does not apply. */
    float lens_radius = ortho ? 0.0f : 0.5f * camera->aperture;

    *view = (PtrView){
        .origin = camera->lookfrom,
        .pixel00 = v3_add(top_left, v3_scale(v3_add(du, dv), 0.5f)),
        .pixel_du = du,
        .pixel_dv = dv,
        .lens_u = v3_scale(u, lens_radius),
        .lens_v = v3_scale(v, lens_radius),
        .orthographic = ortho,
        .forward = v3_scale(w, -1.0f),
        .width = width,
        .height = height,
    };
    return 1;
}
