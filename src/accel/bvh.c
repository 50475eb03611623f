/* The reference traversal of the tree (bvh_build.c builds it).
 *
 * Every ray first tests the huge spheres left out of the tree, then walks the
 * tree front to back: of a node's children it visits the nearest entry
 * first and stacks the others, and it skips any child whose box it enters
 * beyond the best hit so far. Skipping never changes the answer: a box
 * contains its spheres' hits, so a sphere in a skipped box cannot do better
 * than the best hit; and on equal t the sphere first in the arrays wins
 * wherever it was found, so the order of the visits does not matter either.
 *
 * The node test, which the assembly versions compute with exactly these
 * operations in this order (per lane, no FMA; max(a, b) is maxps's
 * a > b ? a : b and min(a, b) minps's a < b ? a : b):
 *
 *   per ray:  inv[a]  = min(max(1 / dir[a], -FLT_MAX), FLT_MAX)
 *             near[a] = the box's lower_a if inv[a] has its sign bit clear,
 *                       else upper_a; far[a] the other one
 *             best_up = best * PTR_BVH_SLACK, again whenever best changes
 *   per box:  tn[a] = (near[a] - org[a]) * inv[a]
 *             tf[a] = (far[a] - org[a]) * inv[a]
 *             entry = max(max(max(tn[x], tn[y]), tn[z]), tmin)
 *             exit  = min(min(min(tf[x], tf[y]), tf[z]) * PTR_BVH_SLACK, best_up)
 *             the ray visits the box if entry <= exit.
 *
 * The clamped reciprocal keeps every product finite or infinite, never NaN
 * (a zero direction component gives +-FLT_MAX, so an origin on a box's face
 * gives 0, not 0 * inf), and choosing the planes by the sign of inv makes an
 * empty lane (lower +inf, upper -inf) give entry +inf and exit -inf.
 *
 * Why the result is the brute-force kernel's: the kernel's t carries a
 * rounding error of a few ulps of the numbers it works with, |org - centre|
 * (about t) and the radius; the box test's t values carry 3 roundings of
 * their own. The part relative to t is absorbed by PTR_BVH_SLACK (2^-18,
 * some 30 ulps, on exit and on best); the part relative to the radius and to
 * the positions involved by the spheres' box padding, 2^-18 of the largest
 * magnitude in the tree plus the radius (bvh_prims.c). The largest magnitude
 * bounds where rays start, because the camera sits at 0 and other rays start
 * on spheres. tests/unit/test_bvh.c checks the answers bit for bit on
 * adversarial scenes (far from the origin, huge and tiny radii, grazing
 * rays). */
#include "accel/bvh.h"

#include <assert.h>
#include <float.h>
#include <math.h>
#include <stddef.h>

#include "accel/sphere_hit.h"

/* The assembly traversal reads these at fixed offsets (asm/layout.inc). */
static_assert(offsetof(PtrBvh, nodes) == 0 && offsetof(PtrBvh, huge_count) == 16,
              "PtrBvh layout");
static_assert(offsetof(PtrBvhNode, lower_x) == 0 && offsetof(PtrBvhNode, upper_x) == 32 &&
              offsetof(PtrBvhNode, lower_y) == 64 && offsetof(PtrBvhNode, lower_z) == 128 &&
              offsetof(PtrBvhNode, child) == 192 && offsetof(PtrBvhNode, leaf_count) == 224 &&
              sizeof(PtrBvhNode) == 256, "PtrBvhNode layout");
/* asm/layout.inc repeats PTR_BVH_SLACK as the float bits 0x3f800020. */
static_assert(PTR_BVH_MAX_DEPTH == 64, "asm/layout.inc's stack size");

typedef struct StackEntry {
    uint32_t child, leaf_count;
    float entry;
} StackEntry;

/* Whether sphere i at distance t beats the best so far; an equal t wins
 * below position tie. */
static inline int better(float t, uint32_t i, float tmin, float best, uint32_t tie)
{
    return t > tmin && (t < best || (t == best && i < tie));
}

PTR_DECL_BVH_CLOSEST_HIT(ptr_bvh_closest_hit_c)
{
    assert(ray->tmin >= 0.0f && ray->tmin < ray->tmax);
    assert(bvh->depth <= PTR_BVH_MAX_DEPTH);
    const float tmin = ray->tmin;
    float best = ray->tmax;
    uint32_t best_index = PTR_NO_HIT;
    uint32_t tie = 0; /* the best's position; 0 before a first hit: no tie with tmax wins */

    for (size_t i = 0; i < bvh->huge_count; i++) {
        const float t = ptr_sphere_hit(ray, spheres, i);
        if (better(t, (uint32_t)i, tmin, best, tie)) {
            best = t;
            best_index = tie = (uint32_t)i;
        }
    }

    if (bvh->nodes) {
        /* Per ray: the reciprocal direction, and which of each axis's two
         * planes is met first, as the offset of its array in a node. */
        float org[3], inv[3];
        size_t near[3], far[3];
        static const size_t lower[3] = { offsetof(PtrBvhNode, lower_x),
                                         offsetof(PtrBvhNode, lower_y),
                                         offsetof(PtrBvhNode, lower_z) };
        static const size_t upper[3] = { offsetof(PtrBvhNode, upper_x),
                                         offsetof(PtrBvhNode, upper_y),
                                         offsetof(PtrBvhNode, upper_z) };
        for (int a = 0; a < 3; a++) {
            org[a] = ray->org[a];
            inv[a] = ptr_minf(ptr_maxf(1.0f / ray->dir[a], -FLT_MAX), FLT_MAX);
            near[a] = signbit(inv[a]) ? upper[a] : lower[a];
            far[a] = signbit(inv[a]) ? lower[a] : upper[a];
        }
        float best_up = best * PTR_BVH_SLACK;
        StackEntry stack[PTR_BVH_MAX_DEPTH * (PTR_BVH_WIDTH - 1) + 1];
        size_t top = 0;
        stack[top++] = (StackEntry){ 0, 0, -INFINITY };
        while (top > 0) {
            const StackEntry e = stack[--top];
            if (e.entry > best_up)
                continue;
            if (e.leaf_count) {
                for (uint32_t i = e.child; i < e.child + e.leaf_count; i++) {
                    const float t = ptr_sphere_hit(ray, spheres, i);
                    if (better(t, i, tmin, best, tie)) {
                        best = t;
                        best_index = tie = i;
                        best_up = best * PTR_BVH_SLACK;
                    }
                }
                continue;
            }
            const PtrBvhNode *node = &bvh->nodes[e.child];
            const char *base = (const char *)node;
            float entry[PTR_BVH_WIDTH], exit[PTR_BVH_WIDTH];
            for (int k = 0; k < PTR_BVH_WIDTH; k++) {
                float tn[3], tf[3];
                for (int a = 0; a < 3; a++) {
                    tn[a] = (((const float *)(base + near[a]))[k] - org[a]) * inv[a];
                    tf[a] = (((const float *)(base + far[a]))[k] - org[a]) * inv[a];
                }
                entry[k] = ptr_maxf(ptr_maxf(ptr_maxf(tn[0], tn[1]), tn[2]), tmin);
                exit[k] = ptr_minf(ptr_minf(ptr_minf(tf[0], tf[1]), tf[2]) * PTR_BVH_SLACK, best_up);
            }
            StackEntry hits[PTR_BVH_WIDTH];
            int n = 0;
            for (int k = 0; k < PTR_BVH_WIDTH; k++) {
                if (!(entry[k] <= exit[k]))
                    continue;
                /* Sorted farthest first, so that the nearest is popped first. */
                int j = n++;
                for (; j > 0 && hits[j - 1].entry < entry[k]; j--)
                    hits[j] = hits[j - 1];
                hits[j] = (StackEntry){ node->child[k], node->leaf_count[k], entry[k] };
            }
            for (int j = 0; j < n; j++)
                stack[top++] = hits[j];
        }
    }
    hit->t = best;
    hit->sphere = best_index;
    return best_index != PTR_NO_HIT;
}
