/* Checks on imported scenes, for the importer tests. */
#ifndef PTR_TEST_SCENE_H
#define PTR_TEST_SCENE_H

#include "scene/scene.h"
#include "test.h"

/* Sphere i is at (x, y, z) in world coordinates (the scene's origin plus the
 * stored offset), within tolerance, with radius r to 1e-6. */
static void check_sphere(const PtrScene *s, size_t i, double x, double y, double z, double r,
                         double tolerance)
{
    CHECK(i < s->spheres.count);
    if (i >= s->spheres.count)
        return;
    CHECK_NEAR(s->origin[0] + s->spheres.cx[i], x, tolerance);
    CHECK_NEAR(s->origin[1] + s->spheres.cy[i], y, tolerance);
    CHECK_NEAR(s->origin[2] + s->spheres.cz[i], z, tolerance);
    CHECK_NEAR(s->spheres.radius[i], r, 1e-6);
}

#endif /* PTR_TEST_SCENE_H */
