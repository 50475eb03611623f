#include "accel/bvh_split.h"

#include <math.h>
#include <string.h>

enum { BINS = 32 };

static void bounds_empty(float lo[3], float hi[3])
{
    for (int a = 0; a < 3; a++) {
        lo[a] = INFINITY;
        hi[a] = -INFINITY;
    }
}

static void bounds_grow(float lo[3], float hi[3], const float plo[3], const float phi[3])
{
    for (int a = 0; a < 3; a++) {
        lo[a] = ptr_minf(lo[a], plo[a]);
        hi[a] = ptr_maxf(hi[a], phi[a]);
    }
}

/* The bins of one run of prims: boxes and counts per axis, plus the run's
 * box. A bin's box is x, y, z and an unused lane in one SSE register, so
 * that growing it is one minimum and one maximum, where three scalar lanes
 * took six (binning is most of a build). _mm_min_ps(a, b) and
 * _mm_max_ps(a, b) are ptr_minf(a, b) and ptr_maxf(a, b) lane by lane, so
 * the boxes have the bits the scalar code gives. */
typedef struct Bins {
    __m128 lower[3][BINS], upper[3][BINS];
    size_t count[3][BINS];
    float box_lo[3], box_hi[3];
} Bins;

static void bins_clear(Bins *b, int bins)
{
    for (int a = 0; a < 3; a++)
        for (int k = 0; k < bins; k++) {
            b->lower[a][k] = _mm_set1_ps(INFINITY);
            b->upper[a][k] = _mm_set1_ps(-INFINITY);
            b->count[a][k] = 0;
        }
    bounds_empty(b->box_lo, b->box_hi);
}

/* bvh_half_area of the box in the x, y and z lanes of lo and hi: its
 * arithmetic in its order, (dx dy + dy dz) + dz dx, without storing the
 * lanes (the sweep over a candidate's bins asks it twice a bin). */
static inline float half_area4(__m128 lo, __m128 hi)
{
    const __m128 d = _mm_sub_ps(hi, lo);
    const __m128 p = _mm_mul_ps(d, _mm_shuffle_ps(d, d, _MM_SHUFFLE(3, 0, 2, 1)));
    return _mm_cvtss_f32(p) + _mm_cvtss_f32(_mm_shuffle_ps(p, p, _MM_SHUFFLE(1, 1, 1, 1))) +
           _mm_cvtss_f32(_mm_shuffle_ps(p, p, _MM_SHUFFLE(2, 2, 2, 2)));
}

/* The box only (of a task's range, or of the root's samples). */
static void bound_run(const BvhPrimSet *set, size_t begin, size_t end, Bins *b)
{
    for (size_t i = begin; i < end; i++) {
        float lower[3], upper[3];
        bvh_prim_box(&set->prims[i], set->magnitude, lower, upper);
        bounds_grow(b->box_lo, b->box_hi, lower, upper);
    }
}

/* Samples far apart are each a cache miss the hardware's prefetchers do
 * not foresee: fetched this many samples ahead, they overlap. */
enum { PREFETCH_SAMPLES = 16 };

/* Every stride-th prim of the run. */
static void bin_run(const BvhPrimSet *set, size_t begin, size_t end, size_t stride,
                    const BvhCandidate *c, Bins *b)
{
    const __m128 base = _mm_setr_ps(c->bin_base[0], c->bin_base[1], c->bin_base[2], 0.0f);
    const __m128 scale = _mm_setr_ps(c->bin_scale[0], c->bin_scale[1], c->bin_scale[2], 0.0f);
    const __m128 last = _mm_set1_ps((float)(c->bins - 1));
    const size_t ahead = stride > 1 ? PREFETCH_SAMPLES * stride : 0;
    for (size_t i = begin; i < end; i += stride) {
        if (ahead && end - i > ahead)
            _mm_prefetch((const char *)&set->prims[i + ahead], _MM_HINT_T0);
        const BvhPrim *p = &set->prims[i];
        __m128 lower, upper;
        bvh_prim_box4(p, set->magnitude, &lower, &upper);
        /* Its bins on the three axes at once (the radius lane, scaled by
         * 0, gives bin 0). */
        int k[4];
        _mm_storeu_si128((__m128i *)k, bvh_bins4(_mm_loadu_ps(p->centre), base, scale, last));
        for (int a = 0; a < 3; a++) {
            b->lower[a][k[a]] = _mm_min_ps(b->lower[a][k[a]], lower);
            b->upper[a][k[a]] = _mm_max_ps(b->upper[a][k[a]], upper);
            b->count[a][k[a]]++;
        }
    }
}

/* Runs of more than SAMPLED_ABOVE prims choose their split from about
 * SAMPLES of them, evenly spaced: at the top of a tree of 10^7 spheres,
 * binning every prim took a third of the build and chose much the same
 * splits. */
enum { SAMPLED_ABOVE = 1 << 16, SAMPLES = 1 << 14 };

void bvh_candidate_init(const BvhPrimSet *set, BvhCandidate *c, size_t begin, size_t end,
                        const float lower[3], const float upper[3])
{
    Bins bins;
    c->begin = begin;
    c->end = end;
    c->axis = -1;
    c->sampled = 0;
    if (!lower) {
        bins_clear(&bins, 0);
        bound_run(set, begin, end, &bins);
        lower = bins.box_lo;
        upper = bins.box_hi;
    }
    memcpy(c->lower, lower, sizeof c->lower);
    memcpy(c->upper, upper, sizeof c->upper);
    if (end - begin <= PTR_BVH_LEAF_MAX)
        return;
    /* Embree's rule: few bins for few prims, where more would mostly be
     * empty and only cost time. */
    c->bins = 4 + (int)((end - begin) / 20);
    if (c->bins > BINS)
        c->bins = BINS;
    int spread = 0;
    for (int a = 0; a < 3; a++) {
        float extent = 2.0f * (c->upper[a] - c->lower[a]);
        c->bin_base[a] = 2.0f * c->lower[a];
        /* Just under bins / extent, so the largest centre lands in the last bin. */
        c->bin_scale[a] = extent > 0.0f ? (float)c->bins * 0.99999f / extent : 0.0f;
        spread |= extent > 0.0f;
    }
    if (!spread)
        return;
    c->sampled = end - begin > SAMPLED_ABOVE;
    bins_clear(&bins, c->bins);
    bin_run(set, begin, end, c->sampled ? (end - begin) / SAMPLES : 1, c, &bins);
    float best = INFINITY;
    for (int a = 0; a < 3; a++) {
        __m128 right_lo[BINS], right_hi[BINS];
        size_t right_count[BINS];
        __m128 lo4 = _mm_set1_ps(INFINITY), hi4 = _mm_set1_ps(-INFINITY);
        size_t n = 0;
        for (int k = c->bins - 1; k > 0; k--) {
            lo4 = _mm_min_ps(lo4, bins.lower[a][k]);
            hi4 = _mm_max_ps(hi4, bins.upper[a][k]);
            n += bins.count[a][k];
            right_lo[k] = lo4;
            right_hi[k] = hi4;
            right_count[k] = n;
        }
        lo4 = _mm_set1_ps(INFINITY);
        hi4 = _mm_set1_ps(-INFINITY);
        n = 0;
        for (int k = 0; k < c->bins - 1; k++) {
            lo4 = _mm_min_ps(lo4, bins.lower[a][k]);
            hi4 = _mm_max_ps(hi4, bins.upper[a][k]);
            n += bins.count[a][k];
            if (n == 0 || right_count[k + 1] == 0)
                continue;
            float cost = half_area4(lo4, hi4) * (float)n +
                         half_area4(right_lo[k + 1], right_hi[k + 1]) * (float)right_count[k + 1];
            if (cost < best) {
                best = cost;
                c->axis = a;
                c->split_bin = k;
                bvh_store3(c->left_lower, lo4);
                bvh_store3(c->left_upper, hi4);
                bvh_store3(c->right_lower, right_lo[k + 1]);
                bvh_store3(c->right_upper, right_hi[k + 1]);
            }
        }
    }
}

BvhSplitTest bvh_split_test(const BvhCandidate *c)
{
    return (BvhSplitTest){ c->axis, c->split_bin, c->bin_base[c->axis], c->bin_scale[c->axis],
                           (float)(c->bins - 1) };
}

/* The boxes of the prims a partition sends left ([0]) and right ([1]): a
 * split chosen from samples learns its halves' boxes in the pass that moves
 * them, not in one more over all of them. */
typedef struct SideBoxes {
    __m128 lower[2], upper[2]; /* x, y, z and an unused lane, as a bin's */
} SideBoxes;

static void sides_empty(SideBoxes *b)
{
    for (int side = 0; side < 2; side++) {
        b->lower[side] = _mm_set1_ps(INFINITY);
        b->upper[side] = _mm_set1_ps(-INFINITY);
    }
}

static inline void sides_add(SideBoxes *b, float magnitude, const BvhPrim *p, size_t side)
{
    if (!b)
        return;
    __m128 lower, upper;
    bvh_prim_box4(p, magnitude, &lower, &upper);
    b->lower[side] = _mm_min_ps(b->lower[side], lower);
    b->upper[side] = _mm_max_ps(b->upper[side], upper);
}

/* Moves the prims begin .. end - 1 that go left by test before those
 * that go right, adding their boxes to *sides if given; returns the first
 * right one. Hoare's partition. */
static size_t partition_run(BvhPrim *p, float magnitude, size_t begin, size_t end,
                            const BvhSplitTest *test, SideBoxes *sides)
{
    size_t i = begin, j = end;
    for (;;) {
        while (i < j && !bvh_goes_right(test, &p[i]))
            sides_add(sides, magnitude, &p[i++], 0);
        while (i < j && bvh_goes_right(test, &p[j - 1]))
            sides_add(sides, magnitude, &p[--j], 1);
        if (i >= j)
            return i;
        BvhPrim t = p[i];
        p[i] = p[j - 1];
        p[j - 1] = t;
        sides_add(sides, magnitude, &p[i++], 0);
        sides_add(sides, magnitude, &p[--j], 1);
    }
}

/* The same split as partition_run, without its unpredictable branches
 * (Edelkamp and Weiss's BlockQuicksort): blocks at each end are classified
 * into lists of the prims on the wrong side, without a branch, and the
 * lists swapped pairwise; the few prims left in the middle go to
 * partition_run. Everything before the left block belongs left, everything
 * after the right block right. */
static size_t partition_blocks(BvhPrim *p, float magnitude, size_t begin, size_t end,
                               const BvhSplitTest *test, SideBoxes *sides)
{
    enum { BLOCK = 128 };
    unsigned char wrong_left[BLOCK], wrong_right[BLOCK]; /* offsets in each block */
    size_t l = begin, r = end, left_count = 0, right_count = 0, left_at = 0, right_at = 0;
    while (r - l >= 2 * BLOCK) {
        if (left_count == 0) {
            left_at = 0;
            for (size_t i = 0; i < BLOCK; i++) {
                const size_t right = (size_t)bvh_goes_right(test, &p[l + i]);
                wrong_left[left_count] = (unsigned char)i;
                left_count += right;
                sides_add(sides, magnitude, &p[l + i], right);
            }
        }
        if (right_count == 0) {
            right_at = 0;
            for (size_t i = 0; i < BLOCK; i++) {
                const size_t right = (size_t)bvh_goes_right(test, &p[r - 1 - i]);
                wrong_right[right_count] = (unsigned char)i;
                right_count += 1 - right;
                sides_add(sides, magnitude, &p[r - 1 - i], right);
            }
        }
        const size_t swaps = left_count < right_count ? left_count : right_count;
        for (size_t k = 0; k < swaps; k++) {
            BvhPrim *a = &p[l + wrong_left[left_at + k]], *b = &p[r - 1 - wrong_right[right_at + k]];
            const BvhPrim t = *a;
            *a = *b;
            *b = t;
        }
        left_count -= swaps;
        right_count -= swaps;
        left_at += swaps;
        right_at += swaps;
        if (left_count == 0)
            l += BLOCK;
        if (right_count == 0)
            r -= BLOCK;
    }
    /* A block half done is classified again: its boxes are added again to
     * the same side, which changes no box. */
    return partition_run(p, magnitude, l, r, test, sides);
}

/* The same split as partition_run, keeping each side's order, through
 * scratch (room for the run): no branch on the side a prim goes to, which
 * for a random cloud is a coin toss the processor mispredicts half the
 * time. */
static size_t partition_stable(BvhPrim *p, float magnitude, size_t begin, size_t end,
                               const BvhSplitTest *test, BvhPrim *scratch, SideBoxes *sides)
{
    size_t left = begin, right = 0;
    for (size_t i = begin; i < end; i++) {
        const BvhPrim prim = p[i];
        const size_t goes_right = (size_t)bvh_goes_right(test, &prim);
        p[left] = prim;
        scratch[right] = prim;
        left += 1 - goes_right;
        right += goes_right;
        sides_add(sides, magnitude, &prim, goes_right);
    }
    memcpy(p + left, scratch, right * sizeof *p);
    return left;
}

/* Moves the prims of c that go left before those that go right, adding
 * their boxes to *sides if given (emptied first); returns the first right
 * one. With scratch, partition_stable, else partition_blocks. */
static size_t partition(const BvhPrimSet *set, const BvhCandidate *c, BvhPrim *scratch,
                        SideBoxes *sides)
{
    const BvhSplitTest test = bvh_split_test(c);
    if (sides)
        sides_empty(sides);
    if (scratch)
        return partition_stable(set->prims, set->magnitude, c->begin, c->end, &test, scratch,
                                sides);
    return partition_blocks(set->prims, set->magnitude, c->begin, c->end, &test, sides);
}

void bvh_split(const BvhPrimSet *set, const BvhCandidate *c, int middle, BvhPrim *scratch,
               BvhCandidate *left, BvhCandidate *right)
{
    const size_t begin = c->begin, end = c->end;
    size_t mid = begin + (end - begin) / 2;
    /* The halves' boxes: unknown (NULL) for a split in the middle or one
     * chosen from samples, which knows them only once its prims are moved;
     * the bins of one from every prim know them already. */
    const float *box[2][2] = { { NULL, NULL }, { NULL, NULL } };
    SideBoxes sides;
    float side_box[2][2][3];
    const BvhCandidate whole = *c;
    if (!middle && whole.axis >= 0) {
        mid = partition(set, &whole, scratch, whole.sampled ? &sides : NULL);
        for (int side = 0; side < 2; side++) {
            if (whole.sampled) {
                bvh_store3(side_box[side][0], sides.lower[side]);
                bvh_store3(side_box[side][1], sides.upper[side]);
            }
            box[side][0] = whole.sampled ? side_box[side][0]
                                         : side ? whole.right_lower : whole.left_lower;
            box[side][1] = whole.sampled ? side_box[side][1]
                                         : side ? whole.right_upper : whole.left_upper;
        }
    }
    bvh_candidate_init(set, left, begin, mid, box[0][0], box[0][1]);
    bvh_candidate_init(set, right, mid, end, box[1][0], box[1][1]);
}
