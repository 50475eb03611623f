/* Splitting a range of prims in two by the binned surface area heuristic,
 * and into a node's children as a plan from samples says: the building
 * blocks of the tree's build (bvh_build.c). */
#ifndef PTR_BVH_SPLIT_H
#define PTR_BVH_SPLIT_H

#include <stddef.h>

#include "accel/bvh.h"
#include "accel/bvh_prims.h"
#include "base/cpu.h"

/* A range of prims being split into a node's children: its box, and the
 * best binned split found for it with the boxes of its two halves. */
typedef struct BvhCandidate {
    size_t begin, end;
    float lower[3], upper[3];
    int axis;         /* of the best split; -1: split in the middle of the range */
    int bins;         /* BVH_BINS, fewer for small ranges */
    int split_bin;    /* prims in bins <= split_bin go left */
    float left_lower[3], left_upper[3], right_lower[3], right_upper[3];
    /* Binning: a prim's bin on axis a is (lower + upper - bin_base) * bin_scale,
     * over the candidate's box (cheaper than the box of the centres, which
     * would need a pass of its own, and as good for spheres of similar size). */
    float bin_base[3], bin_scale[3];
} BvhCandidate;

enum { BVH_BINS = 32 }; /* BvhCandidate.bins at most */

/* A candidate's bins: for each axis and bin, the box of the prims whose
 * centres fall in it and their count, in eight floats: the box's lower x,
 * y and z negated and a lane no one reads, then its upper x, y and z and
 * the count (exact: a range binned has at most BVH_PLANNED_ABOVE prims).
 * With the lower corner negated, a prim grows its bin by maxima alone: one
 * 256-bit maximum (bvh_bin_avx2) or two 128-bit ones (bvh_bin_c), where
 * separate lower and upper corners took a minimum and a maximum, each a
 * load and a store of its own. Negated exactly (the sign flipped, so a +0
 * corner is -0), max(-a, -b) is -min(a, b) bit for bit, ties and zeros'
 * signs included (_mm_max_ps(x, y) is x > y ? x : y, and _mm_min_ps(a, b)
 * is a < b ? a : b), and upper - lower is upper + (-lower) exactly, so the
 * boxes and areas are the same bits as before. */
typedef struct BvhBins {
    _Alignas(32) float box[3][BVH_BINS][8];
} BvhBins;

/* Empties c->bins bins an axis: corners of -infinity (a maximum's
 * identity), no prims. */
void bvh_bins_clear(const BvhCandidate *c, BvhBins *bins);

/* Grows c->bins bins an axis, emptied by bvh_bins_clear, by the count
 * prims (c's range), each in its bin on each axis (bvh_bins4 of its centre
 * over c's bin_base and bin_scale), and touches no other bin. Every
 * version leaves the same bits in every lane but the unread one. */
#define PTR_DECL_BVH_BIN(name)                                                \
    void name(const BvhPrim *prims, size_t count, float magnitude,            \
              const BvhCandidate *c, BvhBins *bins)

typedef PTR_DECL_BVH_BIN((*BvhBinFn));

/* The reference, in SSE2. */
PTR_DECL_BVH_BIN(bvh_bin_c);
#if PTR_HAVE_BVH_BIN_AVX2
/* One 256-bit maximum a bin (bvh_bin_avx2.c, built for AVX2). */
PTR_DECL_BVH_BIN(bvh_bin_avx2);
#endif

/* The binning at a CPU level (the caller's, as ptr_bvh_build's). */
typedef struct BvhBinKernel {
    BvhBinFn bin;
    const char *name; /* "c", "avx2" */
} BvhBinKernel;

BvhBinKernel bvh_bin_for_level(PtrCpuLevel level);

/* What prim p grows its bins by: its padded box's lower corner negated
 * and its upper corner (bvh_prim_box4's), 0 in the upper's fourth lane
 * for the count (the lower's fourth lane is unread). */
static inline void bvh_bin_box(const BvhPrim *p, float magnitude, __m128 *neg_lower,
                               __m128 *upper)
{
    __m128 lower;
    bvh_prim_box4(p, magnitude, &lower, upper);
    /* The sign flipped, not extent - centre: that is +0 where centre -
     * extent is +0, whose negation is -0. */
    *neg_lower = _mm_xor_ps(lower, _mm_set1_ps(-0.0f));
    *upper = _mm_and_ps(*upper, _mm_castsi128_ps(_mm_setr_epi32(-1, -1, -1, 0)));
}

/* What a bin's eight lanes grow by after their maximum: one on the count,
 * and -0 on the rest, which leaves every float as it is (x + -0 is x, -0
 * included). */
#define BVH_BIN_ONE_MORE -0.0f, -0.0f, -0.0f, -0.0f, -0.0f, -0.0f, -0.0f, 1.0f

/* The prims being built over, and how they are binned. */
typedef struct BvhPrimSet {
    BvhPrim *prims;
    float magnitude; /* of the coordinates, for the boxes (see ptr_bvh_prims) */
    BvhBinFn bin;    /* bvh_bin_for_level's, at the build's CPU level */
} BvhPrimSet;

/* Half the surface area of a box: what the heuristic weighs. */
static inline float bvh_half_area(const float lo[3], const float hi[3])
{
    float dx = hi[0] - lo[0], dy = hi[1] - lo[1], dz = hi[2] - lo[2];
    return dx * dy + dy * dz + dz * dx;
}

/* Ranges of more than this many prims are split into a node's children
 * by a plan from samples (bvh_build.c), not a split at a time: at the top
 * of a tree of 10^8 spheres, a pass over a range's prims for each of its
 * node's three levels of splits took a third of the build. */
enum { BVH_PLANNED_ABOVE = 1 << 16 };

/* Sets c to the range begin .. end - 1 with box lower, upper (NULL: find
 * it) and, if it has more prims than a leaf holds and no more than
 * BVH_PLANNED_ABOVE, finds its best split (else c->axis is -1). */
void bvh_candidate_init(const BvhPrimSet *set, BvhCandidate *c, size_t begin, size_t end,
                        const float lower[3], const float upper[3]);

/* c's best split (c->axis at least 0) as its prims are tested against it. */
BvhSplitTest bvh_split_test(const BvhCandidate *c);

/* The least centre on the axis of c's best split that goes right by it:
 * bvh_goes_right_at's arithmetic is monotone in the centre (doubling,
 * subtracting the base, multiplying by a scale above 0, clamping and
 * truncating each are), so a prim of c goes right exactly when its centre
 * is at least this. c's box must hold every centre of its prims (a prim's
 * padded box holds its centre), as it does for a candidate the build
 * makes; the float found is one of the box's, or the one just above it
 * where no centre in the box goes right. */
float bvh_least_right(const BvhCandidate *c);

/* Splits c in two (into *left and *right, which may be c), keeping each
 * half's order: by its best split, or in the middle of its order if it has
 * none or middle is set. scratch: room for BVH_PLANNED_ABOVE prims (no
 * range of more is partitioned, see bvh_candidate_init). */
void bvh_split(const BvhPrimSet *set, const BvhCandidate *c, int middle, BvhPrim *scratch,
               BvhCandidate *left, BvhCandidate *right);

/* Prims a block of bvh_split_children's sort: 3 KB, which moves as a stream
 * the prefetchers follow. The blocks being filled, one a bucket (8 for a
 * node's children, 24 KB; up to 64 for their children, 192 KB), stay in a
 * level-2 cache of 512 KB or more; a worker's sort room keeps 194 blocks
 * (582 KB) of buffers. */
enum { BVH_SORT_BLOCK = 128 };

/* What bvh_split_children works in, kept from one sort to the next: a
 * byte a prim (its bucket) and a word a block of the largest range sorted,
 * and its buffers. */
typedef struct BvhSortRoom {
    uint8_t *bucket;
    uint32_t *dest;
    BvhPrim *blocks;
    size_t prims; /* room for */
} BvhSortRoom;

/* Makes room for sorting prims prims; fails only for memory
 * (PTR_ERR_NOMEM, no message). */
PtrResult bvh_sort_room_reserve(BvhSortRoom *room, size_t prims);
void bvh_sort_room_free(BvhSortRoom *room);

/* Sorts the prims begin .. end - 1 into children (its splits set, from
 * samples), in place and stably (each child's prims in the order they
 * came), in bvh_children_order's order, and fills in each child's range
 * and box. With grandchildren (else NULL), each child k's prims are sorted
 * in the same pass into its own children by grandchildren[k]'s splits (a
 * count of 1: none), as a second call on the child's range would sort them
 * (stably within each of its children), and grandchildren[k]'s ranges and
 * boxes are filled in too. room: reserved for end - begin prims. */
void bvh_split_children(const BvhPrimSet *set, size_t begin, size_t end, BvhChildren *children,
                        BvhChildren *grandchildren, BvhSortRoom *room);

#endif /* PTR_BVH_SPLIT_H */
