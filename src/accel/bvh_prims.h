/* What the tree is built from: a padded box per sphere, the choice of the
 * huge spheres it keeps out of its boxes, the copy that sorts the others
 * into the root's children, and the splits of a node planned from samples
 * (BvhChildren), with which the copy and bvh_split_children sort. */
#ifndef PTR_BVH_PRIMS_H
#define PTR_BVH_PRIMS_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <emmintrin.h> /* SSE2, which every x86-64 CPU has */

#include "accel/bvh.h"
#include "base/result.h"
#include "scene/scene.h"

/* A sphere as the build moves it, whole, in 24 bytes. At 10^8 spheres the
 * prims are the build's largest array, and the scene's arrays give their
 * pages up to them as they are filled; the tree's leaves are written back
 * to the arrays from the prims, in their final order. No prim needs its
 * place in the file: every split keeps the prims' order, so a leaf's come
 * in the arrays' (see bvh_split). */
typedef struct BvhPrim {
    float centre[3], radius;
    /* The rest of the sphere, where it fits (bvh_rest_by_place): its
     * material's index in material_size bytes, then the entry of each
     * attribute it has (PTR_SPHERE_ATTRIBUTES), from the lowest byte up:
     * so 2 for the material and 6 for the colour in a scene of up to
     * 65,536 materials. Else its place in the arrays, where the build
     * reads the rest back from (bvh_rest_aside). */
    uint64_t rest;
} BvhPrim;

_Static_assert(sizeof(BvhPrim) == 24, "a prim is 24 bytes");
_Static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
               "rest's entries are copied in and out as the low bytes of a word");

/* Box padding, relative to the magnitude of the numbers involved: see the
 * traversal's comment in bvh.c for why 2^-18. */
#define BVH_BOX_PAD_SCALE 0x1.0p-18f

/* Half the side of a prim's padded box; magnitude: see ptr_bvh_prims. */
static inline float bvh_prim_extent(const BvhPrim *p, float magnitude)
{
    return p->radius + BVH_BOX_PAD_SCALE * (magnitude + p->radius);
}

/* The padded box of a prim, the same bits wherever it is computed. */
static inline void bvh_prim_box(const BvhPrim *p, float magnitude, float lower[3],
                                float upper[3])
{
    const float extent = bvh_prim_extent(p, magnitude);
    for (int a = 0; a < 3; a++) {
        lower[a] = p->centre[a] - extent;
        upper[a] = p->centre[a] + extent;
    }
}

/* bvh_prim_box in registers: x, y, z and, in the unused lane, the radius
 * less and plus the extent. */
static inline void bvh_prim_box4(const BvhPrim *p, float magnitude, __m128 *lower,
                                 __m128 *upper)
{
    const __m128 centre = _mm_loadu_ps(p->centre),
                 extent = _mm_set1_ps(bvh_prim_extent(p, magnitude));
    *lower = _mm_sub_ps(centre, extent);
    *upper = _mm_add_ps(centre, extent);
}

/* A binned split as a prim is tested against it: whether the prim's bin on
 * the split's axis, (2 centre - base) scale clamped to the bins, is past
 * split_bin (bvh_split.c's bins: 2 centre is the box's lower + upper). */
typedef struct BvhSplitTest {
    int axis, split_bin;
    float base, scale, last; /* last: the bins less 1 */
} BvhSplitTest;

/* Whether a prim whose centre on the split's axis is x goes right. */
static inline int bvh_goes_right_at(const BvhSplitTest *t, float x)
{
    /* Clamped as a float, then converted: no branch, and a NaN-free range. */
    const float k = (2.0f * x - t->base) * t->scale;
    return (int)ptr_minf(ptr_maxf(k, 0.0f), t->last) > t->split_bin;
}

/* Four bins at once, bvh_goes_right_at's arithmetic lane by lane: centre +
 * centre is 2 centre, and _mm_min_ps(a, b) and _mm_max_ps(a, b) are
 * ptr_minf(a, b) and ptr_maxf(a, b). */
static inline __m128i bvh_bins4(__m128 centre, __m128 base, __m128 scale, __m128 last)
{
    const __m128 at = _mm_mul_ps(_mm_sub_ps(_mm_add_ps(centre, centre), base), scale);
    return _mm_cvttps_epi32(_mm_min_ps(_mm_max_ps(at, _mm_setzero_ps()), last));
}

/* The x, y and z lanes of v. */
static inline void bvh_store3(float out[3], __m128 v)
{
    float lanes[4];
    _mm_storeu_ps(lanes, v);
    memcpy(out, lanes, 3 * sizeof *out);
}

/* A node's children as its splits make them, chosen from samples of its
 * prims before the prims are sorted into them (bvh_build.c's plans): split
 * s, for s from 1 to count - 1 in turn, sends the prims of child source[s]
 * that go right by test[s] to child s; every prim starts in child 0. The
 * sort (ptr_bvh_prims for the root, bvh_split_children for a node) fills
 * in each child's prims, begin .. end - 1, and padded box. */
typedef struct BvhChildren {
    int count;
    int source[PTR_BVH_WIDTH];
    BvhSplitTest test[PTR_BVH_WIDTH];
    size_t begin[PTR_BVH_WIDTH], end[PTR_BVH_WIDTH];
    float lower[PTR_BVH_WIDTH][3], upper[PTR_BVH_WIDTH][3];
} BvhChildren;

/* A BvhChildren's splits in four lanes each, to find the children of four
 * prims at once. */
typedef struct BvhChildLanes {
    int count;
    int axis[PTR_BVH_WIDTH];
    __m128 base[PTR_BVH_WIDTH], scale[PTR_BVH_WIDTH], last[PTR_BVH_WIDTH];
    __m128i split_bin[PTR_BVH_WIDTH], source[PTR_BVH_WIDTH];
} BvhChildLanes;

void bvh_child_lanes(const BvhChildren *children, BvhChildLanes *lanes);

/* The children of four prims whose centres' x, y and z are centre[0], [1]
 * and [2], in child[0 .. 3]: each split moves the lanes in its source that
 * go right (bvh_goes_right_at's arithmetic, bvh_bins4). */
static inline void bvh_children4(const BvhChildLanes *l, const __m128 centre[3], uint8_t child[4])
{
    __m128i in = _mm_setzero_si128();
    for (int s = 1; s < l->count; s++) {
        const __m128i bin = bvh_bins4(centre[l->axis[s]], l->base[s], l->scale[s], l->last[s]);
        const __m128i moves = _mm_and_si128(_mm_cmpgt_epi32(bin, l->split_bin[s]),
                                            _mm_cmpeq_epi32(in, l->source[s]));
        in = _mm_or_si128(_mm_andnot_si128(moves, in), _mm_and_si128(moves, _mm_set1_epi32(s)));
    }
    /* The four children, each below 8, in the four low bytes. */
    const __m128i words = _mm_packs_epi32(in, in);
    const uint32_t four = (uint32_t)_mm_cvtsi128_si32(_mm_packus_epi16(words, words));
    memcpy(child, &four, sizeof four);
}

/* The children in the order a split in place leaves them, order[0 ..
 * count - 1]: the prims a split sends right follow those it leaves in its
 * source. */
void bvh_children_order(const BvhChildren *children, int order[PTR_BVH_WIDTH]);

/* Puts the huge spheres (scene.h's rule, with the tree's limit) in
 * huge[0 .. *huge_count - 1] (by ascending id; room for PTR_HUGE_MAX) and
 * their indices, ascending, in huge_index, counting and choosing on this
 * many threads (ptr_thread_count's count). Fails only for memory. */
PtrResult ptr_bvh_huge(const PtrSpheres *spheres, int threads, BvhPrim *huge,
                       size_t *huge_index, size_t *huge_count, PtrError *err);

/* Puts in samples up to max of the spheres but the huge ones (huge_index,
 * ascending), evenly spaced, or all of them if they are no more, gathered
 * on this many threads; returns their count, and their magnitude (see
 * ptr_bvh_prims) in *magnitude. */
size_t ptr_bvh_samples(const PtrSpheres *spheres, int threads, const size_t *huge_index,
                       size_t huge_count, BvhPrim *samples, size_t max, float *magnitude);

/* Puts a prim for each sphere but the huge ones (huge_index, ascending) in
 * prims, sorted into the children (in the arrays' order within each), their
 * count in *prim_count, and in *magnitude the largest coordinate magnitude
 * in the tree, which bounds both the spheres' and the rays' origins (the
 * camera sits at 0, other rays start on spheres) and so scales the boxes'
 * padding. Gives up the spheres' memory as it goes (ptr_spheres_release),
 * through bank (empty when called): each step's prims go on the pages of
 * the spheres copied the step before, and the last step's stay in bank for
 * the write-back. On success the prims and the huge spheres hold the only
 * copy of spheres 0 .. count - 1 but their values (and but their material
 * and attributes where bvh_rest_aside set them aside).
 * Counts and copies on this many threads; the prims' order does not depend
 * on their number. Fails only for memory: the spheres untouched, but where
 * the kernel ran out of memory moving pages (ptr_pages_take), when some are
 * already given up, as they are where the build fails after this. */
PtrResult ptr_bvh_prims(PtrSpheres *spheres, int threads, const size_t *huge_index,
                        size_t huge_count, BvhChildren *children, BvhPrim *prims,
                        size_t *prim_count, float *magnitude, PtrPageBank *bank,
                        PtrError *err);

/* Fails for memory the tree's build cannot have: every failure of the
 * build's functions is this one. (The code returned as a constant, so the
 * compiler sees that no output is used after a failure.) */
static inline PtrResult bvh_out_of_memory(PtrError *err)
{
    ptr_error_set(err, PTR_ERR_NOMEM, "out of memory building the tree");
    return PTR_ERR_NOMEM;
}

/* Whether the rest of a sphere of s (its material and attributes) is too
 * large for BvhPrim.rest, which then holds its place: where a scene of
 * more than 65,536 materials gives its spheres colours. */
int bvh_rest_by_place(const PtrSpheres *s);

/* For a build where bvh_rest_by_place: moves s's material and attribute
 * arrays to *aside and gives s fresh ones, whose entries from count on (the
 * spheres the tree leaves in place) are copied, for the write-back to
 * gather each sphere's from aside. Fails only for memory, s as it was. */
PtrResult bvh_rest_aside(PtrSpheres *s, size_t count, PtrSpheres *aside, PtrError *err);

/* Frees what bvh_rest_aside set aside (nothing if it set nothing). */
void bvh_rest_free(PtrSpheres *aside);

/* Sphere i of s as a prim, whole; and its centre and radius alone (rest
 * 0), as samples need. */
BvhPrim bvh_prim_of(const PtrSpheres *s, size_t i);
BvhPrim bvh_prim_geometry(const PtrSpheres *s, size_t i);

/* Stores p as sphere i of s, the rest read from aside where it is set
 * aside (bvh_rest_aside), else NULL. */
void bvh_prim_store(const BvhPrim *p, PtrSpheres *s, size_t i, const PtrSpheres *aside);

#endif /* PTR_BVH_PRIMS_H */
