/* A camera prepared for one image size: a thin lens (perspective) or
 * parallel rays (orthographic). */
#ifndef PTR_CAMERA_H
#define PTR_CAMERA_H

#include "scene/scene.h"

typedef struct PtrView {
    PtrVec3 origin;
    /* Centre of the top-left pixel: on the focus plane (perspective), on the
     * near plane (orthographic). */
    PtrVec3 pixel00;
    PtrVec3 pixel_du;     /* one pixel to the right */
    PtrVec3 pixel_dv;     /* one pixel down */
    PtrVec3 lens_u, lens_v; /* lens radius along the camera's right and up */
    int orthographic;     /* rays start at their pixel and run along forward */
    PtrVec3 forward;      /* unit view direction */
    int width, height;
} PtrView;

/* Returns 0 if the camera is degenerate (look-from equals look-at, up parallel
 * to the view direction, negative aperture; perspective: field of view
 * outside (0, 180) or non-positive focus distance; orthographic: ymag not
 * above 0 or znear negative). */
int ptr_view_init(PtrView *view, const PtrCamera *camera, int width, int height);

/* A primary ray through pixel (x, y) at the sub-pixel offset (sx, sy) in
 * [0, 1)^2 from the pixel's corner, leaving the lens at (lx, ly) in the unit
 * disc (an orthographic view has no lens and ignores them). The direction is
 * normalised. */
static inline void ptr_view_ray(const PtrView *view, int x, int y, float sx, float sy,
                                float lx, float ly, PtrVec3 *origin, PtrVec3 *dir)
{
    PtrVec3 target = v3_add(view->pixel00,
                            v3_add(v3_scale(view->pixel_du, (float)x + sx - 0.5f),
                                   v3_scale(view->pixel_dv, (float)y + sy - 0.5f)));
    if (view->orthographic) {
        *origin = target;
        *dir = view->forward;
        return;
    }
    PtrVec3 o = v3_add(view->origin,
                       v3_add(v3_scale(view->lens_u, lx), v3_scale(view->lens_v, ly)));
    *origin = o;
    *dir = v3_normalize(v3_sub(target, o));
}

#endif /* PTR_CAMERA_H */
