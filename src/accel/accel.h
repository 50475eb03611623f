/* How the renderer finds closest hits: brute force over all spheres, or the
 * tree, chosen once per render by the number of spheres; either way after the
 * scene's huge spheres, which are tested in double (accel/huge.h). The path
 * tracer makes every query through ptr_trace. */
#ifndef PTR_ACCEL_H
#define PTR_ACCEL_H

#include <stddef.h>

#include "accel/bvh.h"
#include "accel/huge.h"
#include "accel/isect.h"
#include "core/result.h"
#include "core/scene.h"

typedef enum PtrAccelChoice {
    PTR_ACCEL_AUTO,  /* brute force below the crossover, else the tree */
    PTR_ACCEL_BRUTE,
    PTR_ACCEL_BVH,
} PtrAccelChoice;

/* The sphere counts from which the tree beats brute force, measured with
 * `bench/bvh --crossover` (cloud scenes, 200x113, 4 spp, 2 threads; see
 * docs/intersectors.md, "Choosing"), on an AVX2 machine. With the C
 * kernels the C traversal overtakes brute force between 16 spheres (5.5
 * against 5.2 Mrays/s) and 32 (3.7 against 4.6); the AVX2 brute-force
 * kernel holds out against the C traversal up to between 256 (3.9 against
 * 3.2) and 512 (1.7 against 2.3), and against the AVX2 traversal up to the
 * same place (256: 5.8 against 3.9; 512: 2.5 against 3.4, 2 spp). */
enum { PTR_ACCEL_CROSSOVER_C = 24, PTR_ACCEL_CROSSOVER_ASM = 384 };

/* The crossover for brute force with isect's kernel. */
size_t ptr_accel_crossover(const PtrIsectTable *isect);

typedef struct PtrAccel {
    PtrAccelChoice kind;       /* PTR_ACCEL_BRUTE or PTR_ACCEL_BVH */
    const PtrScene *scene;
    const PtrSpheres *spheres; /* the scene's, as the tree reordered them */
    size_t searched;           /* spheres brute force or the tree covers: all but the huge */
    PtrIsectTable isect;
    PtrBvh bvh;                /* empty for brute force */
    double build_seconds;
} PtrAccel;

/* Chooses and prepares the structure for the scene's spheres with the
 * kernels of isect; the tree reorders the spheres (all arrays together; see
 * bvh.h). threads: for the build, 0 for one per CPU. Only PTR_ERR_NOMEM can
 * fail. */
PtrResult ptr_accel_init(PtrAccel *accel, PtrAccelChoice choice, const PtrIsectTable *isect,
                         PtrScene *scene, int threads);

/* Brute force over the scene's spheres as they are: nothing to build or free. */
PtrAccel ptr_accel_brute(const PtrIsectTable *isect, const PtrScene *scene);

void ptr_accel_free(PtrAccel *accel);

/* "brute" or "bvh". */
const char *ptr_accel_name(const PtrAccel *accel);

/* Parses "auto", "brute" or "bvh"; returns 0 if it is none of them. */
int ptr_accel_parse(const char *text, PtrAccelChoice *choice);

/* The closest hit along ray, as PTR_DECL_CLOSEST_HIT describes it; on equal
 * distances the sphere first in the scene file wins, whichever structure. */
static inline int ptr_search(const PtrAccel *accel, const PtrRay *ray, PtrHit *hit)
{
    if (accel->kind == PTR_ACCEL_BVH)
        return accel->isect.bvh_closest_hit(ray, &accel->bvh, accel->spheres, hit);
    return accel->isect.closest_hit(ray, accel->spheres, accel->searched, hit);
}

/* ptr_trace for scenes with huge spheres. */
int ptr_trace_huge_first(const PtrAccel *accel, const PtrRay *ray, PtrHit *hit);

static inline int ptr_trace(const PtrAccel *accel, const PtrRay *ray, PtrHit *hit)
{
    if (accel->scene->huge.count)
        return ptr_trace_huge_first(accel, ray, hit);
    return ptr_search(accel, ray, hit);
}

#endif /* PTR_ACCEL_H */
