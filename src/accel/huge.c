#include "accel/huge.h"

#include <math.h>

/* The spawn offset: rounding the re-projected point to float moves each
 * coordinate by at most 2^-24 of its magnitude, so at most sqrt(3) 2^-24 of
 * the largest one across the surface; twice that, rounded up to a power of
 * two, keeps the new origin on the side the ray goes to. The second term
 * covers the double-precision test itself, whose f.f - r^2 is good to a few
 * ulps of r^2, i.e. a height of about 2^-52 r. */
#define SPAWN_POINT_SCALE 0x1.0p-21
#define SPAWN_RADIUS_SCALE 0x1.0p-48

static const double *huge_sphere(const PtrScene *scene, uint32_t sphere)
{
    size_t first = scene->spheres.count - scene->huge.count;
    return &scene->huge.centre_radius[4 * (sphere - first)];
}

/* The float kernel's formulation (see ptr_closest_hit_c), in double. */
int ptr_huge_closest_hit(const PtrRay *ray, const PtrScene *scene, PtrHit *hit)
{
    const PtrHugeSpheres *huge = &scene->huge;
    const size_t first = scene->spheres.count - huge->count;
    const double ox = ray->org[0], oy = ray->org[1], oz = ray->org[2];
    const double dx = ray->dir[0], dy = ray->dir[1], dz = ray->dir[2];
    const double tmin = ray->tmin;
    double best = ray->tmax;
    uint32_t best_index = PTR_NO_HIT;

    for (size_t i = 0; i < huge->count; i++) {
        const double *s = &huge->centre_radius[4 * i];
        const double fx = ox - s[0], fy = oy - s[1], fz = oz - s[2], r = s[3];
        const double b = fx * dx + fy * dy + fz * dz;
        const double vx = fx - b * dx, vy = fy - b * dy, vz = fz - b * dz;
        const double r2 = r * r;
        const double disc = r2 - (vx * vx + vy * vy + vz * vz);
        if (!(disc >= 0.0))
            continue;
        const double c = (fx * fx + fy * fy + fz * fz) - r2;
        const double q = -b - copysign(sqrt(disc), b);
        const double t0 = c / q, t1 = q;
        const double near = t0 < t1 ? t0 : t1;
        const double far = t0 > t1 ? t0 : t1;
        const double t = near > tmin ? near : far;
        /* Strict <: on equal t the first in the arrays wins, as everywhere. */
        if (t > tmin && t < best) {
            best = t;
            best_index = (uint32_t)(first + i);
        }
    }
    hit->t = (float)best;
    hit->sphere = best_index;
    return best_index != PTR_NO_HIT;
}

/* p re-projected onto huge sphere s, and the outward normal there. */
static void reproject(const double *s, const double p[3], double point[3], double normal[3])
{
    double length2 = 0;
    for (int k = 0; k < 3; k++) {
        normal[k] = p[k] - s[k];
        length2 += normal[k] * normal[k];
    }
    const double inverse = 1.0 / sqrt(length2);
    for (int k = 0; k < 3; k++) {
        normal[k] *= inverse;
        point[k] = s[k] + s[3] * normal[k];
    }
}

void ptr_huge_surface(const PtrScene *scene, const PtrRay *ray, const PtrHit *hit,
                      PtrVec3 *point, PtrVec3 *normal)
{
    double p[3], on[3], n[3];
    for (int k = 0; k < 3; k++)
        p[k] = (double)ray->org[k] + (double)ray->dir[k] * (double)hit->t;
    reproject(huge_sphere(scene, hit->sphere), p, on, n);
    *point = v3((float)on[0], (float)on[1], (float)on[2]);
    *normal = v3((float)n[0], (float)n[1], (float)n[2]);
}

PtrRay ptr_huge_spawn_ray(const PtrScene *scene, uint32_t sphere, PtrVec3 point, PtrVec3 dir)
{
    const double *s = huge_sphere(scene, sphere);
    const double p[3] = { point.x, point.y, point.z };
    double on[3], normal[3];
    reproject(s, p, on, normal);
    const double largest = fmax(fabs(on[0]), fmax(fabs(on[1]), fabs(on[2])));
    double offset = SPAWN_POINT_SCALE * largest + SPAWN_RADIUS_SCALE * s[3];
    if (dir.x * normal[0] + dir.y * normal[1] + dir.z * normal[2] < 0.0)
        offset = -offset;
    PtrRay out = { .tmin = 0.0f, .dir = { dir.x, dir.y, dir.z }, .tmax = INFINITY };
    for (int k = 0; k < 3; k++)
        out.org[k] = (float)(on[k] + offset * normal[k]);
    return out;
}
