/* A bounding volume hierarchy over a scene's spheres: 8-wide nodes whose
 * child boxes are stored lane by lane, so one SIMD step tests a ray against
 * all eight, and leaves that are short runs of the scene's own sphere arrays,
 * so the leaf test is the brute-force kernel's arithmetic on a few lanes.
 *
 * The build reorders the scene's spheres (all per-sphere arrays together,
 * see ptr_spheres_permute) so that every leaf is contiguous, and keeps the
 * few spheres much larger than the rest out of the tree: they come first in
 * the arrays and every ray tests them, as the brute-force kernel would.
 *
 * The result contract is the brute-force kernel's: the closest hit with its
 * t bit for bit, and on equal t the sphere that came first in the scene
 * file (the lowest PtrSpheres.id), so that an image never depends on
 * whether a tree was used. */
#ifndef PTR_BVH_H
#define PTR_BVH_H

#include <stddef.h>
#include <stdint.h>

#include "core/result.h"
#include "core/scene.h"

enum {
    PTR_BVH_WIDTH = 8,    /* children per node */
    PTR_BVH_LEAF_MAX = 8, /* spheres per leaf at most */
};

/* 256 bytes, 64-byte aligned: the assembly reads it at fixed offsets
 * (asm/ptr.inc). */
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
    /* Spheres 0 .. unbounded_count - 1 of the reordered arrays are not in
     * the tree (they would ruin it: a huge ground under tiny spheres); every
     * ray tests them first. */
    size_t unbounded_count;
    int depth; /* levels below the root at most, for the traversal stack */
} PtrBvh;

#endif /* PTR_BVH_H */
