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
#include "base/result.h"
#include "scene/scene.h"

typedef enum PtrAccelChoice {
    PTR_ACCEL_AUTO,  /* brute force below the crossover, else the tree */
    PTR_ACCEL_BRUTE,
    PTR_ACCEL_BVH,
} PtrAccelChoice;

/* The sphere counts from which the tree beats brute force, measured with
 * `bench/bvh --crossover 200 113 8` (cloud scenes, 2 threads; see
 * docs/intersectors.md, "Choosing"), on an AVX2 machine. With the C kernels
 * (paths one at a time) the C traversal overtakes brute force between 16
 * and 32 spheres. With the SSE4.1 kernel (paths one at a time) against the
 * C traversal: 64 spheres 8.4 against 8.2 Mrays/s, 128 6.0 against 7.7. On
 * an AVX2 CPU (bundles of paths: the packet kernel against the AVX2
 * traversal lane by lane): 128 spheres 12.9 against 12.0, 256 6.7 against
 * 11.1. Macros, so that --help can spell them out. */
#define PTR_ACCEL_CROSSOVER_C 24
#define PTR_ACCEL_CROSSOVER_SSE41 96
#define PTR_ACCEL_CROSSOVER_AVX2 192

/* The crossover for brute force with isect's kernel, asked one ray at a time
 * or (packets) eight at a time by bundles of paths. */
size_t ptr_accel_crossover(const PtrIsectTable *isect, int packets);

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
 * kernels of isect; the tree's build reorders the spheres (all arrays
 * together; see bvh.h), for brute force too, which then searches them in
 * that order; packets as for ptr_accel_crossover. threads: for the build, 0 for
 * one per CPU the process may run on. Fails only with PTR_ERR_NOMEM, said in err (which may be NULL). */
PtrResult ptr_accel_init(PtrAccel *accel, PtrAccelChoice choice, const PtrIsectTable *isect,
                         int packets, PtrScene *scene, int threads, PtrError *err);

/* Brute force over the scene's spheres as they are: nothing to build or
 * free. (A render's brute force, ptr_accel_init's, searches them in the
 * build's order.) */
PtrAccel ptr_accel_brute(const PtrIsectTable *isect, const PtrScene *scene);

void ptr_accel_free(PtrAccel *accel);

/* "brute" or "bvh". */
const char *ptr_accel_name(const PtrAccel *accel);

/* Parses "auto", "brute" or "bvh"; PTR_ERR_USAGE for anything else. */
PtrResult ptr_accel_parse(const char *text, PtrAccelChoice *choice, PtrError *err);

/* The closest hit along ray, as PTR_DECL_CLOSEST_HIT describes it; on equal
 * distances the sphere first in the arrays wins, whichever structure. */
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
