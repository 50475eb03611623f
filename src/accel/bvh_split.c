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
 * box. A bin's box is x, y, z and a fourth lane in one SSE register, so
 * that growing it is one minimum and one maximum, where three scalar lanes
 * took six (binning is most of a build). _mm_min_ps(a, b) and
 * _mm_max_ps(a, b) are ptr_minf(a, b) and ptr_maxf(a, b) lane by lane, so
 * the boxes have the bits the scalar code gives. The bin's count is the
 * upper box's fourth lane, a float (exact: a range binned has at most
 * BVH_PLANNED_ABOVE prims), so that counting a prim is no load and store of
 * its own. */
typedef struct Bins {
    __m128 lower[3][BINS], upper[3][BINS];
    float box_lo[3], box_hi[3];
} Bins;

static void bins_clear(Bins *b, int bins)
{
    for (int a = 0; a < 3; a++)
        for (int k = 0; k < bins; k++) {
            b->lower[a][k] = _mm_set1_ps(INFINITY);
            b->upper[a][k] = _mm_setr_ps(-INFINITY, -INFINITY, -INFINITY, 0.0f);
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

/* A bin's count, or a sum of them: the fourth lane (see Bins). */
static inline float count_lane(__m128 upper)
{
    return _mm_cvtss_f32(_mm_shuffle_ps(upper, upper, _MM_SHUFFLE(3, 3, 3, 3)));
}

/* The box only (of a plan's samples, or of the halves of a split in the
 * middle). */
static void bound_run(const BvhPrimSet *set, size_t begin, size_t end, Bins *b)
{
    for (size_t i = begin; i < end; i++) {
        float lower[3], upper[3];
        bvh_prim_box(&set->prims[i], set->magnitude, lower, upper);
        bounds_grow(b->box_lo, b->box_hi, lower, upper);
    }
}

static void bin_run(const BvhPrimSet *set, size_t begin, size_t end, const BvhCandidate *c,
                    Bins *b)
{
    const __m128 base = _mm_setr_ps(c->bin_base[0], c->bin_base[1], c->bin_base[2], 0.0f);
    const __m128 scale = _mm_setr_ps(c->bin_scale[0], c->bin_scale[1], c->bin_scale[2], 0.0f);
    const __m128 last = _mm_set1_ps((float)(c->bins - 1));
    /* The box's upper x, y and z, and 0 under the count; then one more on
     * the count, 0 on the box (x + 0 is x but for x = -0, and no box has a
     * -0: the extent is never -0, so centre + extent is -0 only for a
     * centre of -0 and an extent of -0). */
    const __m128 box_lanes = _mm_castsi128_ps(_mm_setr_epi32(-1, -1, -1, 0)),
                 one_more = _mm_setr_ps(0.0f, 0.0f, 0.0f, 1.0f);
    for (size_t i = begin; i < end; i++) {
        const BvhPrim *p = &set->prims[i];
        __m128 lower, upper;
        bvh_prim_box4(p, set->magnitude, &lower, &upper);
        upper = _mm_and_ps(upper, box_lanes);
        /* Its bins on the three axes at once (the radius lane, scaled by
         * 0, gives bin 0). */
        int k[4];
        _mm_storeu_si128((__m128i *)k, bvh_bins4(_mm_loadu_ps(p->centre), base, scale, last));
        for (int a = 0; a < 3; a++) {
            b->lower[a][k[a]] = _mm_min_ps(b->lower[a][k[a]], lower);
            b->upper[a][k[a]] = _mm_add_ps(_mm_max_ps(b->upper[a][k[a]], upper), one_more);
        }
    }
}

void bvh_candidate_init(const BvhPrimSet *set, BvhCandidate *c, size_t begin, size_t end,
                        const float lower[3], const float upper[3])
{
    Bins bins;
    c->begin = begin;
    c->end = end;
    c->axis = -1;
    if (!lower) {
        bins_clear(&bins, 0);
        bound_run(set, begin, end, &bins);
        lower = bins.box_lo;
        upper = bins.box_hi;
    }
    memcpy(c->lower, lower, sizeof c->lower);
    memcpy(c->upper, upper, sizeof c->upper);
    if (end - begin <= PTR_BVH_LEAF_MAX || end - begin > BVH_PLANNED_ABOVE)
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
    bins_clear(&bins, c->bins);
    bin_run(set, begin, end, c, &bins);
    float best = INFINITY;
    for (int a = 0; a < 3; a++) {
        /* The boxes of the bins from each end, and their counts summed in
         * the fourth lane of sum (hi4's fourth lane, their largest count,
         * is no box's). */
        __m128 right_lo[BINS], right_hi[BINS];
        float right_count[BINS];
        __m128 lo4 = _mm_set1_ps(INFINITY), hi4 = _mm_set1_ps(-INFINITY), sum = _mm_setzero_ps();
        for (int k = c->bins - 1; k > 0; k--) {
            lo4 = _mm_min_ps(lo4, bins.lower[a][k]);
            hi4 = _mm_max_ps(hi4, bins.upper[a][k]);
            sum = _mm_add_ps(sum, bins.upper[a][k]);
            right_lo[k] = lo4;
            right_hi[k] = hi4;
            right_count[k] = count_lane(sum);
        }
        lo4 = _mm_set1_ps(INFINITY);
        hi4 = _mm_set1_ps(-INFINITY);
        sum = _mm_setzero_ps();
        for (int k = 0; k < c->bins - 1; k++) {
            lo4 = _mm_min_ps(lo4, bins.lower[a][k]);
            hi4 = _mm_max_ps(hi4, bins.upper[a][k]);
            sum = _mm_add_ps(sum, bins.upper[a][k]);
            const float n = count_lane(sum);
            if (n == 0 || right_count[k + 1] == 0)
                continue;
            float cost = half_area4(lo4, hi4) * n +
                         half_area4(right_lo[k + 1], right_hi[k + 1]) * right_count[k + 1];
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

/* Moves the prims begin .. end - 1 that go left by test before those
 * that go right; returns the first right one. Hoare's partition. */
static size_t partition_run(BvhPrim *p, size_t begin, size_t end, const BvhSplitTest *test)
{
    size_t i = begin, j = end;
    for (;;) {
        while (i < j && !bvh_goes_right(test, &p[i]))
            i++;
        while (i < j && bvh_goes_right(test, &p[j - 1]))
            j--;
        if (i >= j)
            return i;
        BvhPrim t = p[i];
        p[i++] = p[j - 1];
        p[--j] = t;
    }
}

/* The same split as partition_run, without its unpredictable branches
 * (Edelkamp and Weiss's BlockQuicksort): blocks at each end are classified
 * into lists of the prims on the wrong side, without a branch, and the
 * lists swapped pairwise; the few prims left in the middle go to
 * partition_run. Everything before the left block belongs left, everything
 * after the right block right. */
static size_t partition_blocks(BvhPrim *p, size_t begin, size_t end, const BvhSplitTest *test)
{
    enum { BLOCK = 128 };
    unsigned char wrong_left[BLOCK], wrong_right[BLOCK]; /* offsets in each block */
    size_t l = begin, r = end, left_count = 0, right_count = 0, left_at = 0, right_at = 0;
    while (r - l >= 2 * BLOCK) {
        if (left_count == 0) {
            left_at = 0;
            for (size_t i = 0; i < BLOCK; i++) {
                wrong_left[left_count] = (unsigned char)i;
                left_count += (size_t)bvh_goes_right(test, &p[l + i]);
            }
        }
        if (right_count == 0) {
            right_at = 0;
            for (size_t i = 0; i < BLOCK; i++) {
                wrong_right[right_count] = (unsigned char)i;
                right_count += 1 - (size_t)bvh_goes_right(test, &p[r - 1 - i]);
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
    return partition_run(p, l, r, test);
}

/* The same split as partition_run, keeping each side's order, through
 * scratch (room for the run): no branch on the side a prim goes to, which
 * for a random cloud is a coin toss the processor mispredicts half the
 * time. */
static size_t partition_stable(BvhPrim *p, size_t begin, size_t end, const BvhSplitTest *test,
                               BvhPrim *scratch)
{
    size_t left = begin, right = 0;
    for (size_t i = begin; i < end; i++) {
        const BvhPrim prim = p[i];
        const size_t goes_right = (size_t)bvh_goes_right(test, &prim);
        p[left] = prim;
        scratch[right] = prim;
        left += 1 - goes_right;
        right += goes_right;
    }
    memcpy(p + left, scratch, right * sizeof *p);
    return left;
}

/* Moves the prims of c that go left before those that go right; returns
 * the first right one. With scratch, partition_stable, else
 * partition_blocks. */
static size_t partition(const BvhPrimSet *set, const BvhCandidate *c, BvhPrim *scratch)
{
    const BvhSplitTest test = bvh_split_test(c);
    if (scratch)
        return partition_stable(set->prims, c->begin, c->end, &test, scratch);
    return partition_blocks(set->prims, c->begin, c->end, &test);
}

void bvh_split(const BvhPrimSet *set, const BvhCandidate *c, int middle, BvhPrim *scratch,
               BvhCandidate *left, BvhCandidate *right)
{
    const BvhCandidate whole = *c;
    const int binned = !middle && whole.axis >= 0;
    /* The halves' boxes are the bins' for a binned split, and unknown
     * (NULL) for one in the middle. */
    const size_t mid = binned ? partition(set, &whole, scratch)
                              : whole.begin + (whole.end - whole.begin) / 2;
    bvh_candidate_init(set, left, whole.begin, mid, binned ? whole.left_lower : NULL,
                       binned ? whole.left_upper : NULL);
    bvh_candidate_init(set, right, mid, whole.end, binned ? whole.right_lower : NULL,
                       binned ? whole.right_upper : NULL);
}

/* The children of the prims p[0 .. 3] in child[0 .. 3], four at once: their
 * centres' rows turned into columns. */
static void prim_children4(const BvhChildLanes *lanes, const BvhPrim *p, uint8_t child[4])
{
    __m128 x = _mm_loadu_ps(p[0].centre), y = _mm_loadu_ps(p[1].centre),
           z = _mm_loadu_ps(p[2].centre), radius = _mm_loadu_ps(p[3].centre);
    _MM_TRANSPOSE4_PS(x, y, z, radius);
    const __m128 centre[3] = { x, y, z };
    bvh_children4(lanes, centre, child);
}

/* The children's counts and boxes, growing with each prim. */
typedef struct ChildBoxes {
    size_t count[PTR_BVH_WIDTH];
    __m128 lower[PTR_BVH_WIDTH], upper[PTR_BVH_WIDTH];
} ChildBoxes;

/* Finds the children of the first n (at most 4) of the prims p, in child,
 * and adds the prims to their children's counts and boxes. */
static void add_children4(const BvhChildLanes *lanes, float magnitude, const BvhPrim *p,
                          size_t n, uint8_t *child, ChildBoxes *b)
{
    uint8_t four[4];
    if (n == 4) {
        prim_children4(lanes, p, four);
    } else {
        /* The last prims of a range: the lanes past them repeat the last. */
        BvhPrim last[4];
        for (size_t i = 0; i < 4; i++)
            last[i] = p[i < n ? i : n - 1];
        prim_children4(lanes, last, four);
    }
    for (size_t i = 0; i < n; i++) {
        const int k = four[i];
        __m128 lower, upper;
        bvh_prim_box4(&p[i], magnitude, &lower, &upper);
        b->lower[k] = _mm_min_ps(b->lower[k], lower);
        b->upper[k] = _mm_max_ps(b->upper[k], upper);
        b->count[k]++;
        child[i] = (uint8_t)k;
    }
}

void bvh_split_children(const BvhPrimSet *set, size_t begin, size_t end, BvhChildren *children,
                        uint8_t *child)
{
    BvhChildLanes lanes;
    bvh_child_lanes(children, &lanes);
    BvhPrim *p = set->prims + begin;
    const size_t n = end - begin;
    ChildBoxes b = { .count = { 0 } };
    for (int k = 0; k < children->count; k++) {
        b.lower[k] = _mm_set1_ps(INFINITY);
        b.upper[k] = _mm_set1_ps(-INFINITY);
    }
    for (size_t i = 0; i < n; i += 4)
        add_children4(&lanes, set->magnitude, &p[i], n - i < 4 ? n - i : 4, &child[i], &b);
    /* Each child's place, and the next of its places to fill (head). */
    int order[PTR_BVH_WIDTH];
    size_t head[PTR_BVH_WIDTH], stop[PTR_BVH_WIDTH], next = 0;
    bvh_children_order(children, order);
    for (int j = 0; j < children->count; j++) {
        const int k = order[j];
        head[k] = next;
        next += b.count[k];
        stop[k] = next;
        children->begin[k] = begin + head[k];
        children->end[k] = begin + next;
        bvh_store3(children->lower[k], b.lower[k]);
        bvh_store3(children->upper[k], b.upper[k]);
    }
    /* Each child's places in turn, filled by swaps (American flag sort):
     * a prim that belongs elsewhere goes to its child's next place, whose
     * prim is looked at next. Each swap puts one prim in its child. */
    for (int j = 0; j < children->count; j++) {
        const int k = order[j];
        while (head[k] < stop[k]) {
            const size_t at = head[k];
            const int to = child[at];
            if (to == k) {
                head[k]++;
                continue;
            }
            const size_t there = head[to]++;
            const BvhPrim moved = p[there];
            p[there] = p[at];
            p[at] = moved;
            child[at] = child[there];
            child[there] = (uint8_t)to;
        }
    }
}
