#include "naive.h"

#include <math.h>

PTR_DECL_CLOSEST_HIT(naive_closest_hit)
{
    float best = ray->tmax;
    uint32_t best_index = PTR_NO_HIT;
    for (size_t i = 0; i < count; i++) {
        float fx = ray->org[0] - spheres->cx[i];
        float fy = ray->org[1] - spheres->cy[i];
        float fz = ray->org[2] - spheres->cz[i];
        float r = spheres->radius[i];
        float b = fx * ray->dir[0] + fy * ray->dir[1] + fz * ray->dir[2];
        float c = fx * fx + fy * fy + fz * fz - r * r;
        float disc = b * b - c;
        if (!(disc >= 0.0f))
            continue;
        float s = sqrtf(disc);
        float t = -b - s;
        if (!(t > ray->tmin))
            t = -b + s;
        if (t > ray->tmin && t < best) {
            best = t;
            best_index = (uint32_t)i;
        }
    }
    hit->t = best;
    hit->sphere = best_index;
    return best_index != PTR_NO_HIT;
}
