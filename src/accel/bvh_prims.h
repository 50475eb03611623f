/* What the tree is built from: a padded box per sphere, and the choice of
 * the spheres kept out of the tree. */
#ifndef PTR_BVH_PRIMS_H
#define PTR_BVH_PRIMS_H

#include <stddef.h>
#include <stdint.h>

#include "scene/scene.h"

typedef struct BvhPrim {
    float lower[3], upper[3];
    uint32_t index; /* of the sphere in the arrays as they were before the build */
    uint32_t id;    /* the sphere's id, which orders a leaf */
} BvhPrim;

/* Puts the spheres kept out of the tree at order[0 .. *unbounded_count - 1]
 * (by ascending id) and a box for each of the others in prims (their count
 * in *prim_count, in the arrays' order). Returns 0 if out of memory. */
int ptr_bvh_prims(const PtrSpheres *spheres, uint32_t *order, size_t *unbounded_count,
                  BvhPrim *prims, size_t *prim_count);

/* Sorts a leaf's prims by ascending sphere id. */
void ptr_bvh_sort_leaf(BvhPrim *prims, size_t count);

#endif /* PTR_BVH_PRIMS_H */
