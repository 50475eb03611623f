/* Rays leaving a sphere's surface: the normal where a ray met it, and a new
 * ray from there that cannot meet the same surface again at t ~ 0. */
#ifndef PTR_SPAWN_H
#define PTR_SPAWN_H

#include <math.h>

#include "accel/ray.h"
#include "base/vec.h"
#include "scene/scene.h"

/* Where a ray from org along dir meets the sphere of this centre and radius
 * at distance t: the outward unit normal there, and the point on the surface
 * (re-projected from the ray's, whose error grows with t). */
static inline void ptr_sphere_surface(PtrVec3 centre, float radius, PtrVec3 org, PtrVec3 dir,
                                      float t, PtrVec3 *point, PtrVec3 *normal)
{
    *normal = v3_normalize(v3_sub(v3_madd(org, dir, t), centre));
    *point = v3_madd(centre, *normal, radius);
}

/* A ray leaving the surface of a sphere along dir from the point where
 * outward_normal meets it: its origin is that point pushed off the surface,
 * along the normal and to the side dir goes, by a bound on the float error of
 * locating it, so that it cannot hit the same surface again at t ~ 0.
 *
 * How far: relative to the
 * magnitude of the numbers that locate it (|centre| + radius): the point is
 * re-projected onto the sphere, which leaves a few ulps of that magnitude of
 * error, and the kernel's f.f - r^2 adds a few more. Measured by
 * tests/stability/test_precision.c over 2 million hit points per level
 * (radii 1e-4 to 1e6, centres up to 1e7 away, down to grazing): 2^-23 lets
 * outward rays hit their own sphere again, 2^-22 stops grazing inward rays
 * short of the far side, 2^-21 and above never fail. Smaller is better (the
 * offset shifts contact shadows), so the smallest safe power of two. */
#define PTR_SPAWN_OFFSET_SCALE 0x1.0p-21f

static inline PtrRay ptr_spawn_ray(PtrVec3 centre, float radius, PtrVec3 outward_normal,
                                   PtrVec3 dir)
{
    float offset = PTR_SPAWN_OFFSET_SCALE * (v3_max_abs(centre) + radius);
    offset = v3_dot(dir, outward_normal) < 0.0f ? -offset : offset;
    PtrVec3 o = v3_add(centre, v3_scale(outward_normal, radius + offset));
    return (PtrRay){ { o.x, o.y, o.z }, 0.0f, { dir.x, dir.y, dir.z }, INFINITY };
}

#endif /* PTR_SPAWN_H */
