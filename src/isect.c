#include "isect.h"

#include <assert.h>
#include <math.h>

/* The formulation avoids the cancellation of the textbook b*b - 4ac: the
 * discriminant is r^2 minus the squared distance from the centre to the ray's
 * line, and the second root comes from the product of roots (c / q), not
 * from a difference of nearly equal numbers. With a unit direction the
 * quadratic is t^2 + 2bt + c = 0, where b = f.d and c = f.f - r^2.
 *
 * Assembly versions must compute exactly these operations in this order
 * (no FMA, IEEE division and square root) so that they agree bit for bit;
 * the selects are written as minps/maxps/cmpps compute them. */
PTR_DECL_CLOSEST_HIT(ptr_closest_hit_c)
{
    assert(count <= spheres->capacity);
    const float ox = ray->org[0], oy = ray->org[1], oz = ray->org[2];
    const float dx = ray->dir[0], dy = ray->dir[1], dz = ray->dir[2];
    const float tmin = ray->tmin;
    float best = ray->tmax;
    uint32_t best_index = PTR_NO_HIT;

    for (size_t i = 0; i < count; i++) {
        const float fx = ox - spheres->cx[i];
        const float fy = oy - spheres->cy[i];
        const float fz = oz - spheres->cz[i];
        const float r = spheres->radius[i];
        const float b = fx * dx + fy * dy + fz * dz;
        const float vx = fx - b * dx;
        const float vy = fy - b * dy;
        const float vz = fz - b * dz;
        const float r2 = r * r;
        const float disc = r2 - (vx * vx + vy * vy + vz * vz);
        if (!(disc >= 0.0f)) /* also rejects the NaN radius of padding */
            continue;
        const float c = (fx * fx + fy * fy + fz * fz) - r2;
        const float q = -b - copysignf(sqrtf(disc), b);
        const float t0 = c / q;
        const float t1 = q;
        const float near = t0 < t1 ? t0 : t1;
        const float far = t0 > t1 ? t0 : t1;
        const float t = near > tmin ? near : far;
        if (t > tmin && t < best) {
            best = t;
            best_index = (uint32_t)i;
        }
    }
    hit->t = best;
    hit->sphere = best_index;
    return best_index != PTR_NO_HIT;
}

int ptr_isect_init(PtrIsectTable *table, PtrKernel kernel)
{
    table->closest_hit = ptr_closest_hit_c;
    table->name = "c";
    switch (kernel) {
    case PTR_KERNEL_AUTO:
    case PTR_KERNEL_C:
        return 1;
    }
    return 0;
}
