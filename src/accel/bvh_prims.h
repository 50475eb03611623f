/* What the tree is built from: a padded box per sphere, and the choice of
 * the spheres kept out of the tree. */
#ifndef PTR_BVH_PRIMS_H
#define PTR_BVH_PRIMS_H

#include <stddef.h>
#include <stdint.h>

#include "scene/scene.h"

enum { BVH_UNBOUNDED_MAX = 16 }; /* spheres kept out of the tree, at most */

/* 24 bytes: at 10^8 spheres the prims are the build's largest array. */
typedef struct BvhPrim {
    float centre[3];
    float extent;   /* the padded box's half width */
    uint32_t index; /* of the sphere in the arrays as they were before the build */
    uint32_t id;    /* the sphere's id, which orders a leaf */
} BvhPrim;

/* The padded box of a prim, the same bits wherever it is computed. */
static inline void bvh_prim_box(const BvhPrim *p, float lower[3], float upper[3])
{
    for (int a = 0; a < 3; a++) {
        lower[a] = p->centre[a] - p->extent;
        upper[a] = p->centre[a] + p->extent;
    }
}

/* Puts the spheres kept out of the tree at order[0 .. *unbounded_count - 1]
 * (by ascending id; order has room for BVH_UNBOUNDED_MAX) and a box for
 * each of the others in prims (their count
 * in *prim_count, in the arrays' order). Returns 0 if out of memory. */
int ptr_bvh_prims(const PtrSpheres *spheres, uint32_t *order, size_t *unbounded_count,
                  BvhPrim *prims, size_t *prim_count);

/* Sorts a leaf's prims by ascending sphere id. */
void ptr_bvh_sort_leaf(BvhPrim *prims, size_t count);

#endif /* PTR_BVH_PRIMS_H */
