#include "accel/accel.h"

#include "accel/cpu.h"

#include <string.h>

PtrAccel ptr_accel_brute(const PtrIsectTable *isect, const PtrSpheres *spheres)
{
    return (PtrAccel){ .kind = PTR_ACCEL_BRUTE, .spheres = spheres, .isect = *isect };
}

PtrResult ptr_accel_init(PtrAccel *accel, PtrAccelChoice choice, const PtrIsectTable *isect,
                         PtrSpheres *spheres, int threads)
{
    *accel = ptr_accel_brute(isect, spheres);
    if (choice == PTR_ACCEL_BRUTE ||
        (choice == PTR_ACCEL_AUTO && spheres->count < ptr_accel_crossover(isect)))
        return PTR_OK;
    double start = ptr_now_seconds();
    PtrResult r = ptr_bvh_build(&accel->bvh, spheres, threads);
    if (r != PTR_OK)
        return r;
    accel->kind = PTR_ACCEL_BVH;
    accel->build_seconds = ptr_now_seconds() - start;
    return PTR_OK;
}

size_t ptr_accel_crossover(const PtrIsectTable *isect)
{
    return isect->closest_hit == ptr_closest_hit_c ? PTR_ACCEL_CROSSOVER_C
                                                   : PTR_ACCEL_CROSSOVER_ASM;
}

void ptr_accel_free(PtrAccel *accel)
{
    ptr_bvh_free(&accel->bvh);
}

const char *ptr_accel_name(const PtrAccel *accel)
{
    return accel->kind == PTR_ACCEL_BVH ? "bvh" : "brute";
}

int ptr_accel_parse(const char *text, PtrAccelChoice *choice)
{
    static const char *const names[] = { "auto", "brute", "bvh" };
    for (int i = 0; i < 3; i++)
        if (!strcmp(text, names[i])) {
            *choice = (PtrAccelChoice)i;
            return 1;
        }
    return 0;
}
