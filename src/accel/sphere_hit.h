/* The per-sphere arithmetic of every closest-hit query, in one place: the
 * brute-force kernel and the tree's leaves both call it, so their t values
 * agree bit for bit. */
#ifndef PTR_SPHERE_HIT_H
#define PTR_SPHERE_HIT_H

#include <math.h>

#include "accel/ray.h"
#include "scene/scene.h"

/* The distance at which the ray enters sphere i, or leaves it if it starts
 * inside (the far root when the near one is not above tmin); NaN if the
 * ray's line misses the sphere. The caller accepts t only if tmin < t.
 *
 * The formulation avoids the cancellation of the textbook b*b - 4ac: the
 * discriminant is r^2 minus the squared distance from the centre to the ray's
 * line, and the second root comes from the product of roots (c / q), not
 * from a difference of nearly equal numbers. With a unit direction the
 * quadratic is t^2 + 2bt + c = 0, where b = f.d and c = f.f - r^2.
 *
 * Assembly versions must compute exactly these operations in this order
 * (no FMA, IEEE division and square root) so that they agree bit for bit;
 * the selects are written as minps/maxps/cmpps compute them. */
static inline float ptr_sphere_hit(const PtrRay *ray, const PtrSpheres *spheres, size_t i)
{
    const float dx = ray->dir[0], dy = ray->dir[1], dz = ray->dir[2];
    const float fx = ray->org[0] - spheres->cx[i];
    const float fy = ray->org[1] - spheres->cy[i];
    const float fz = ray->org[2] - spheres->cz[i];
    const float r = spheres->radius[i];
    const float b = fx * dx + fy * dy + fz * dz;
    const float vx = fx - b * dx;
    const float vy = fy - b * dy;
    const float vz = fz - b * dz;
    const float r2 = r * r;
    const float disc = r2 - (vx * vx + vy * vy + vz * vz);
    if (!(disc >= 0.0f)) /* also rejects the NaN radius of padding */
        return NAN;
    const float c = (fx * fx + fy * fy + fz * fz) - r2;
    const float q = -b - copysignf(sqrtf(disc), b);
    const float t0 = c / q;
    const float t1 = q;
    const float near = t0 < t1 ? t0 : t1;
    const float far = t0 > t1 ? t0 : t1;
    return near > ray->tmin ? near : far;
}

#endif /* PTR_SPHERE_HIT_H */
