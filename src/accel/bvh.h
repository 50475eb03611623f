/* A bounding volume hierarchy over a scene's spheres: 8-wide nodes whose
 * child boxes are stored lane by lane, so one SIMD step tests a ray against
 * all eight, and leaves that are short runs of the scene's own sphere arrays,
 * so the leaf test is the brute-force kernel's arithmetic on a few lanes.
 *
 * The build reorders the scene's spheres (every per-sphere array but the
 * --color-by values, see PtrSpheres) so that every leaf is contiguous, and
 * keeps the few huge ones (much larger than the rest: scene.h's rule) out of
 * the tree: they come first in the arrays and every ray tests them, as the
 * brute-force kernel would.
 *
 * The result contract is the brute-force kernel's over the reordered
 * arrays: the closest hit with its t bit for bit, and on equal t the sphere
 * first in the arrays, so that an image never depends on whether the tree
 * or brute force searched them (the renderer always builds: accel.h). */
#ifndef PTR_BVH_H
#define PTR_BVH_H

#include <stddef.h>
#include <stdint.h>

#include "accel/ray.h"
#include "base/cpu.h"
#include "base/result.h"
#include "scene/scene.h"

enum {
    PTR_BVH_WIDTH = 8,    /* children per node */
    PTR_BVH_LEAF_MAX = 16, /* spheres per leaf at most (the SIMD test takes 8 a step) */
    /* Levels below the root at most (the build splits ranges in the middle
     * when the heuristic goes this deep), so a traversal stack of
     * PTR_BVH_MAX_DEPTH * (PTR_BVH_WIDTH - 1) + 1 entries always suffices. */
    PTR_BVH_MAX_DEPTH = 64,
};

/* 1 + 2^-18: the node test's allowance for rounding (see bvh.c). */
#define PTR_BVH_SLACK 0x1.00004p0f

/* 256 bytes, 64-byte aligned: the assembly reads it at fixed offsets
 * (asm/layout.inc). */
typedef struct PtrBvhNode {
    /* Child boxes, one lane per child. An empty lane has lower = +inf and
     * upper = -inf, which no ray enters. Boxes are padded so that a sphere
     * hit the kernel reports always lies inside its box as the node test
     * computes it (see bvh.c). */
    float lower_x[PTR_BVH_WIDTH], upper_x[PTR_BVH_WIDTH];
    float lower_y[PTR_BVH_WIDTH], upper_y[PTR_BVH_WIDTH];
    float lower_z[PTR_BVH_WIDTH], upper_z[PTR_BVH_WIDTH];
    /* Inner child: its index in PtrBvh.nodes. Leaf: the index of its first
     * sphere in the (reordered) scene arrays. */
    uint32_t child[PTR_BVH_WIDTH];
    /* 0 for an inner child or an empty lane, else the leaf's sphere count
     * (1 to PTR_BVH_LEAF_MAX). */
    uint32_t leaf_count[PTR_BVH_WIDTH];
} PtrBvhNode;

typedef struct PtrBvh {
    PtrBvhNode *nodes; /* nodes[0] is the root; NULL if the tree is empty */
    size_t node_count;
    /* Spheres 0 .. huge_count - 1 of the reordered arrays, the huge ones
     * among the tree's (scene.h's rule), are not in it (they would ruin it:
     * a huge ground under tiny spheres); every ray tests them first. */
    size_t huge_count;
    int depth; /* levels below the root at most, for the traversal stack */
} PtrBvh;

/* Builds the tree over the first count spheres, reordering them (see bvh.h's
 * head) and leaving the rest in place after them (the scene's huge spheres,
 * which accel/huge.h tests); threads 0 means one per CPU the process may run
 * on, and level is the caller's CPU level (ptr_cpu_level, or lower), which
 * chooses the binning's code. The tree's bytes depend only on the spheres,
 * never on the thread count or the level. On failure (out of memory) *bvh is
 * empty and the spheres may be part reordered: the scene can only be freed;
 * err (which may be NULL) says so. */
PtrResult ptr_bvh_build(PtrBvh *bvh, PtrSpheres *spheres, size_t count, int threads,
                        PtrCpuLevel level, PtrError *err);

/* The binning a build at this level uses: "c" or "avx2" (--print-dispatch). */
const char *ptr_bvh_bin_name(PtrCpuLevel level);

void ptr_bvh_free(PtrBvh *bvh);

/* The closest hit among the spheres of a tree built over them (bvh.c says
 * how). Same contract as PTR_DECL_CLOSEST_HIT over all spheres->count
 * spheres, and the same answer bit for bit: on equal t the sphere first in
 * the (reordered) arrays wins, wherever the traversal found it. Writes *hit
 * in every case and returns 1 on a hit. */
#define PTR_DECL_BVH_CLOSEST_HIT(name)                                        \
    int name(const PtrRay *ray, const PtrBvh *bvh, const PtrSpheres *spheres, PtrHit *hit)

typedef PTR_DECL_BVH_CLOSEST_HIT((*PtrBvhClosestHitFn));

/* The reference traversal. */
PTR_DECL_BVH_CLOSEST_HIT(ptr_bvh_closest_hit_c);

#endif /* PTR_BVH_H */
