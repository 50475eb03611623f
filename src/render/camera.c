#include "render/camera.h"

#include <math.h>

int ptr_view_init(PtrView *view, const PtrCamera *camera, int width, int height)
{
    PtrVec3 back = v3_sub(camera->lookfrom, camera->lookat);
    PtrVec3 right = v3_cross(camera->up, back);
    float back_len = v3_length(back), right_len = v3_length(right);
    if (!(back_len > 0.0f) || !(right_len > 1e-6f * back_len * v3_length(camera->up)) ||
        !(camera->vfov_deg > 0.0f && camera->vfov_deg < 180.0f) ||
        !(camera->focus_distance > 0.0f) || !(camera->aperture >= 0.0f) ||
        !isfinite(camera->focus_distance) || !isfinite(camera->aperture) ||
        width <= 0 || height <= 0)
        return 0;

    PtrVec3 w = v3_scale(back, 1.0f / back_len);
    PtrVec3 u = v3_scale(right, 1.0f / right_len);
    PtrVec3 v = v3_cross(w, u);

    float half_height = tanf(0.5f * camera->vfov_deg * PTR_PI / 180.0f) *
                        camera->focus_distance;
    float half_width = half_height * (float)width / (float)height;
    PtrVec3 du = v3_scale(u, 2.0f * half_width / (float)width);
    PtrVec3 dv = v3_scale(v, -2.0f * half_height / (float)height);
    PtrVec3 top_left = v3_add(v3_sub(camera->lookfrom, v3_scale(w, camera->focus_distance)),
                              v3_sub(v3_scale(v, half_height), v3_scale(u, half_width)));
    float lens_radius = 0.5f * camera->aperture;

    *view = (PtrView){
        .origin = camera->lookfrom,
        .pixel00 = v3_add(top_left, v3_scale(v3_add(du, dv), 0.5f)),
        .pixel_du = du,
        .pixel_dv = dv,
        .lens_u = v3_scale(u, lens_radius),
        .lens_v = v3_scale(v, lens_radius),
        .width = width,
        .height = height,
    };
    return 1;
}
