/* Spheres far larger than the region the rays live in, tested in double
 * precision.
 *
 * A radius-1e5 ground under a scene a few units across is how many scenes
 * make a floor. In float, f.f - r^2 for a point near such a sphere cancels
 * two numbers near 1e10: its error is about 1e3, which puts the re-hit
 * distance out by ~0.006 units, and the spawn offset that covers it lifts
 * rays by ~0.1. In double the same error is 1e-6 and the geometry near the
 * camera is exact: the limit was the arithmetic, not the scene. So such
 * spheres are kept (last in the scene's arrays, see PtrHugeSpheres) in
 * double precision, every ray tests them in double, and a ray leaving one
 * is pushed off by the error of the point actually computed rather than by
 * a share of the sphere's size.
 *
 * There are few of them (PTR_HUGE_MAX at most), so one scalar routine
 * serves every intersector level: the C reference and every assembly level
 * then agree bit for bit by construction. */
#ifndef PTR_HUGE_H
#define PTR_HUGE_H

#include "accel/isect.h"
#include "scene/scene.h"

/* Among the huge spheres, the closest hit with tmin < t < tmax, computed in
 * double and rounded to float; on equal distances the lowest id. Writes *hit
 * in every case (sphere: the position in the scene's arrays) and returns 1
 * on a hit. */
int ptr_huge_closest_hit(const PtrRay *ray, const PtrScene *scene, PtrHit *hit);

/* Where ray met huge sphere hit->sphere, computed in double: the point
 * re-projected onto the surface, and the outward unit normal there. */
void ptr_huge_surface(const PtrScene *scene, const PtrRay *ray, const PtrHit *hit,
                      PtrVec3 *point, PtrVec3 *normal);

/* A ray leaving huge sphere `sphere` along dir from point (on or next to
 * its surface): the point is re-projected onto the surface in double and
 * pushed off it by a bound on the error of rounding it to float. */
PtrRay ptr_huge_spawn_ray(const PtrScene *scene, uint32_t sphere, PtrVec3 point, PtrVec3 dir);

/* Whether sphere i of the scene's arrays is one of the huge ones. */
static inline int ptr_is_huge(const PtrScene *scene, size_t i)
{
    return i >= scene->spheres.count - scene->huge.count;
}

#endif /* PTR_HUGE_H */
