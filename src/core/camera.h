/* A thin-lens camera prepared for one image size. */
#ifndef PTR_CAMERA_H
#define PTR_CAMERA_H

#include "sampling/rng.h"
#include "core/scene.h"

typedef struct PtrView {
    PtrVec3 origin;
    PtrVec3 pixel00;      /* centre of the top-left pixel, on the focus plane */
    PtrVec3 pixel_du;     /* one pixel to the right */
    PtrVec3 pixel_dv;     /* one pixel down */
    PtrVec3 lens_u, lens_v; /* lens radius along the camera's right and up */
    int width, height;
} PtrView;

/* Returns 0 if the camera is degenerate (look-from equals look-at, up parallel
 * to the view direction, field of view outside (0, 180), non-positive focus
 * distance or negative aperture). */
int ptr_view_init(PtrView *view, const PtrCamera *camera, int width, int height);

/* A primary ray through pixel (x, y) at the sub-pixel offset (sx, sy) in
 * [0, 1)^2 from the pixel's corner, leaving the lens at (lx, ly) in the unit
 * disc. The direction is normalised. */
void ptr_view_ray(const PtrView *view, int x, int y, float sx, float sy,
                  float lx, float ly, PtrVec3 *origin, PtrVec3 *dir);

#endif /* PTR_CAMERA_H */
