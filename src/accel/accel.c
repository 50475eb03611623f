#include "accel/accel.h"

#include <math.h>
#include <string.h>

#include "base/cpu.h"

PtrAccel ptr_accel_brute(const PtrIsectTable *isect, const PtrScene *scene)
{
    return (PtrAccel){ .kind = PTR_ACCEL_BRUTE, .scene = scene, .spheres = &scene->spheres,
                       .searched = scene->spheres.count - scene->huge.count, .isect = *isect };
}

PtrResult ptr_accel_init(PtrAccel *accel, PtrAccelChoice choice, const PtrIsectTable *isect,
                         int packets, PtrScene *scene, int threads, PtrError *err)
{
    *accel = ptr_accel_brute(isect, scene);
    /* Built for brute force too, for its order: on equal t the sphere first
     * in the arrays wins, so both must search the same arrays (PtrSpheres). */
    double start = ptr_now_seconds();
    PtrResult r = ptr_bvh_build(&accel->bvh, &scene->spheres, accel->searched, threads,
                                isect->level, err);
    if (r != PTR_OK)
        return r;
    accel->build_seconds = ptr_now_seconds() - start;
    if (choice == PTR_ACCEL_BRUTE ||
        (choice == PTR_ACCEL_AUTO && accel->searched < ptr_accel_crossover(isect, packets)))
        ptr_bvh_free(&accel->bvh);
    else
        accel->kind = PTR_ACCEL_BVH;
    return PTR_OK;
}

size_t ptr_accel_crossover(const PtrIsectTable *isect, int packets)
{
    if (isect->closest_hit == ptr_closest_hit_c)
        return PTR_ACCEL_CROSSOVER_C;
    return packets ? PTR_ACCEL_CROSSOVER_AVX2 : PTR_ACCEL_CROSSOVER_SSE41;
}

/* The huge spheres in double, then the rest up to that distance, ties
 * included: the huge spheres are last in the arrays, so on equal t the
 * others win, as the first in the arrays always does. */
int ptr_trace_huge_first(const PtrAccel *accel, const PtrRay *ray, PtrHit *hit)
{
    PtrHit huge;
    PtrRay rest = *ray;
    if (ptr_huge_closest_hit(ray, accel->scene, &huge))
        rest.tmax = nextafterf(huge.t, INFINITY);
    if (ptr_search(accel, &rest, hit))
        return 1;
    *hit = huge;
    return huge.sphere != PTR_NO_HIT;
}

void ptr_accel_free(PtrAccel *accel)
{
    ptr_bvh_free(&accel->bvh);
}

const char *ptr_accel_name(const PtrAccel *accel)
{
    return accel->kind == PTR_ACCEL_BVH ? "bvh" : "brute";
}

PtrResult ptr_accel_parse(const char *text, PtrAccelChoice *choice, PtrError *err)
{
    static const char *const names[] = { "auto", "brute", "bvh" };
    for (int i = 0; i < 3; i++)
        if (!strcmp(text, names[i])) {
            *choice = (PtrAccelChoice)i;
            return PTR_OK;
        }
    return ptr_error_set(err, PTR_ERR_USAGE, "'%s' is not auto, brute or bvh", text);
}
