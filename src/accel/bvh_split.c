#include "accel/bvh_split.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

enum {
    /* What bvh_split_children sorts into: a node's children, or their
     * children, eight to a child (see sort_bucket). */
    SORT_BUCKETS = PTR_BVH_WIDTH * PTR_BVH_WIDTH,
    /* bvh_split_children's buffers, in blocks: a block and two of head for
     * each bucket, and two to move blocks through (see sort_in_blocks). */
    SORT_BLOCKS = 3 * SORT_BUCKETS + 2,
};

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

/* The box of the prims begin .. end - 1 (of a plan's samples, or of the
 * halves of a split in the middle). */
static void bound_run(const BvhPrimSet *set, size_t begin, size_t end, float lo[3], float hi[3])
{
    bounds_empty(lo, hi);
    for (size_t i = begin; i < end; i++) {
        float lower[3], upper[3];
        bvh_prim_box(&set->prims[i], set->magnitude, lower, upper);
        bounds_grow(lo, hi, lower, upper);
    }
}

void bvh_bins_clear(const BvhCandidate *c, BvhBins *bins)
{
    const __m128 none = _mm_set1_ps(-INFINITY),
                 no_prims = _mm_setr_ps(-INFINITY, -INFINITY, -INFINITY, 0.0f);
    for (int a = 0; a < 3; a++)
        for (int k = 0; k < c->bins; k++) {
            _mm_store_ps(bins->box[a][k], none);
            _mm_store_ps(bins->box[a][k] + 4, no_prims);
        }
}

PTR_DECL_BVH_BIN(bvh_bin_c)
{
    const __m128 base = _mm_setr_ps(c->bin_base[0], c->bin_base[1], c->bin_base[2], 0.0f);
    const __m128 scale = _mm_setr_ps(c->bin_scale[0], c->bin_scale[1], c->bin_scale[2], 0.0f);
    const __m128 last = _mm_set1_ps((float)(c->bins - 1));
    const float one_more_lanes[8] = { BVH_BIN_ONE_MORE };
    const __m128 one_more = _mm_loadu_ps(one_more_lanes + 4);
    for (size_t i = 0; i < count; i++) {
        __m128 neg_lower, upper;
        bvh_bin_box(&prims[i], magnitude, &neg_lower, &upper);
        /* Its bins on the three axes at once (the radius lane, scaled by
         * 0, gives bin 0). */
        int k[4];
        _mm_storeu_si128((__m128i *)k, bvh_bins4(_mm_loadu_ps(prims[i].centre), base, scale, last));
        for (int a = 0; a < 3; a++) {
            float *box = bins->box[a][k[a]];
            /* The negated lower corner needs no -0 added: adding it
             * changes nothing. */
            _mm_store_ps(box, _mm_max_ps(_mm_load_ps(box), neg_lower));
            _mm_store_ps(box + 4, _mm_add_ps(_mm_max_ps(_mm_load_ps(box + 4), upper), one_more));
        }
    }
}

BvhBinKernel bvh_bin_for_level(PtrCpuLevel level)
{
#if PTR_HAVE_BVH_BIN_AVX2
    if (level >= PTR_CPU_AVX2)
        return (BvhBinKernel){ bvh_bin_avx2, "avx2" };
#else
    (void)level;
#endif
    return (BvhBinKernel){ bvh_bin_c, "c" };
}

const char *ptr_bvh_bin_name(PtrCpuLevel level)
{
    return bvh_bin_for_level(level).name;
}

/* A run of bins merged: the box in the lanes of BvhBins (negated lower
 * corner, upper corner; upper's last lane, the largest count, is no
 * box's), and in the last lane of counts the count. */
typedef struct BinSum {
    __m128 neg_lower, upper, counts;
} BinSum;

static inline BinSum bin_sum_empty(void)
{
    return (BinSum){ _mm_set1_ps(-INFINITY), _mm_set1_ps(-INFINITY), _mm_setzero_ps() };
}

static inline BinSum bin_sum_add(BinSum s, const float box[8])
{
    const __m128 upper = _mm_load_ps(box + 4);
    return (BinSum){ _mm_max_ps(s.neg_lower, _mm_load_ps(box)), _mm_max_ps(s.upper, upper),
                     _mm_add_ps(s.counts, upper) };
}

static inline float bin_sum_count(BinSum s)
{
    return _mm_cvtss_f32(_mm_shuffle_ps(s.counts, s.counts, _MM_SHUFFLE(3, 3, 3, 3)));
}

/* bvh_half_area of the box: its arithmetic in its order, (dx dy + dy dz)
 * + dz dx, without storing the lanes (the sweep over a candidate's bins
 * asks it twice a bin). */
static inline float bin_sum_half_area(BinSum s)
{
    const __m128 d = _mm_add_ps(s.upper, s.neg_lower);
    const __m128 p = _mm_mul_ps(d, _mm_shuffle_ps(d, d, _MM_SHUFFLE(3, 0, 2, 1)));
    return _mm_cvtss_f32(p) + _mm_cvtss_f32(_mm_shuffle_ps(p, p, _MM_SHUFFLE(1, 1, 1, 1))) +
           _mm_cvtss_f32(_mm_shuffle_ps(p, p, _MM_SHUFFLE(2, 2, 2, 2)));
}

static void bin_sum_store(BinSum s, float lower[3], float upper[3])
{
    bvh_store3(lower, _mm_xor_ps(s.neg_lower, _mm_set1_ps(-0.0f)));
    bvh_store3(upper, s.upper);
}

void bvh_candidate_init(const BvhPrimSet *set, BvhCandidate *c, size_t begin, size_t end,
                        const float lower[3], const float upper[3])
{
    c->begin = begin;
    c->end = end;
    c->axis = -1;
    if (lower) {
        memcpy(c->lower, lower, sizeof c->lower);
        memcpy(c->upper, upper, sizeof c->upper);
    } else {
        bound_run(set, begin, end, c->lower, c->upper);
    }
    if (end - begin <= PTR_BVH_LEAF_MAX || end - begin > BVH_PLANNED_ABOVE)
        return;
    /* Embree's rule: few bins for few prims, where more would mostly be
     * empty and only cost time. */
    c->bins = 4 + (int)((end - begin) / 20);
    if (c->bins > BVH_BINS)
        c->bins = BVH_BINS;
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
    BvhBins bins;
    bvh_bins_clear(c, &bins);
    set->bin(set->prims + begin, end - begin, set->magnitude, c, &bins);
    float best = INFINITY;
    for (int a = 0; a < 3; a++) {
        /* The bins from each end merged. */
        BinSum right[BVH_BINS], left = bin_sum_empty(), sum = bin_sum_empty();
        for (int k = c->bins - 1; k > 0; k--)
            right[k] = sum = bin_sum_add(sum, bins.box[a][k]);
        for (int k = 0; k < c->bins - 1; k++) {
            left = bin_sum_add(left, bins.box[a][k]);
            const float n = bin_sum_count(left), right_n = bin_sum_count(right[k + 1]);
            if (n == 0 || right_n == 0)
                continue;
            float cost = bin_sum_half_area(left) * n + bin_sum_half_area(right[k + 1]) * right_n;
            if (cost < best) {
                best = cost;
                c->axis = a;
                c->split_bin = k;
                bin_sum_store(left, c->left_lower, c->left_upper);
                bin_sum_store(right[k + 1], c->right_lower, c->right_upper);
            }
        }
    }
}

BvhSplitTest bvh_split_test(const BvhCandidate *c)
{
    return (BvhSplitTest){ c->axis, c->split_bin, c->bin_base[c->axis], c->bin_scale[c->axis],
                           (float)(c->bins - 1) };
}

/* Floats as integers in the same order, for searching them: x <= y exactly
 * when float_order(x) <= float_order(y), -0 and +0 both 0. */
static int64_t float_order(float x)
{
    int32_t i;
    memcpy(&i, &x, sizeof i);
    return i >= 0 ? i : -(int64_t)(i & INT32_MAX);
}

static float float_at(int64_t order)
{
    const uint32_t i = order >= 0 ? (uint32_t)order : (uint32_t)-order | UINT32_C(0x80000000);
    float x;
    memcpy(&x, &i, sizeof x);
    return x;
}

static int goes_right_at(const BvhSplitTest *t, int64_t order)
{
    return bvh_goes_right_at(t, float_at(order));
}

float bvh_least_right(const BvhCandidate *c)
{
    const BvhSplitTest t = bvh_split_test(c);
    assert(t.scale > 0.0f); /* a split's axis has an extent */
    /* Orders taken to go left (lo) and right (hi), beyond the box, which
     * holds every centre. */
    int64_t lo = float_order(c->lower[t.axis]) - 1, hi = float_order(c->upper[t.axis]) + 1;
    /* Out from the bins' edge in exact arithmetic, by steps that double,
     * then halving: a few tests, where halving over the box alone took 20
     * to 30. */
    const float edge = 0.5f * ((float)(t.split_bin + 1) / t.scale + t.base);
    int64_t guess = isnan(edge) ? lo + 1 : float_order(edge);
    guess = guess <= lo ? lo + 1 : guess >= hi ? hi - 1 : guess;
    const int up = !goes_right_at(&t, guess); /* the least right is above guess */
    *(up ? &lo : &hi) = guess;
    for (int64_t step = 1; hi - lo > 1; step *= 2) {
        const int64_t next = up ? (lo + step < hi ? lo + step : hi - 1)
                                : (hi - step > lo ? hi - step : lo + 1);
        const int right = goes_right_at(&t, next);
        *(right ? &hi : &lo) = next;
        if (right == up) /* past it: it lies between lo and hi */
            break;
    }
    while (hi - lo > 1) {
        const int64_t mid = lo + (hi - lo) / 2;
        if (goes_right_at(&t, mid))
            hi = mid;
        else
            lo = mid;
    }
    return float_at(hi);
}

/* Moves the prims of c that go left before those that go right, keeping
 * each side's order (so that every partition of the build is stable, and a
 * leaf holds its spheres in the arrays' order), through scratch; returns
 * the first right one. A prim's side is one comparison of its centre
 * (bvh_least_right), where the bin's arithmetic took eight steps, and no
 * branch, which for a random cloud is a coin toss the processor
 * mispredicts half the time. */
static size_t partition(const BvhPrimSet *set, const BvhCandidate *c, BvhPrim *scratch)
{
    const float least_right = bvh_least_right(c);
    const int axis = c->axis;
    BvhPrim *p = set->prims;
    size_t left = c->begin, right = 0;
    for (size_t i = c->begin; i < c->end; i++) {
        const size_t goes_right = p[i].centre[axis] >= least_right;
        const BvhPrim prim = p[i];
        p[left] = prim;
        scratch[right] = prim;
        left += 1 - goes_right;
        right += goes_right;
    }
    memcpy(p + left, scratch, right * sizeof *p);
    return left;
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

/* A child's own splits, to find which of its children a prim goes to:
 * split s (1 to 7) in lane s - 1 of two registers, each lane reading its
 * axis's coordinate through a mask, so that one prim meets all of them at
 * once. The prims of a child meet its splits one prim at a time, where
 * bvh_children4 takes four prims through one split at a time: four prims
 * of one range go to different children, each with its own splits. The
 * splits that send a prim right, as bits, give its child through a table
 * of the chain of sources (BvhChildren). */
typedef struct SplitLanes {
    __m128 on_x[2], on_y[2], on_z[2];
    __m128 base[2], scale[2], last[2];
    __m128i split_bin[2];
    uint8_t child[1 << (PTR_BVH_WIDTH - 1)];
} SplitLanes;

_Static_assert(PTR_BVH_WIDTH - 1 <= 2 * 4, "a node's splits fit two registers' lanes");
_Static_assert(SORT_BUCKETS <= 256, "a bucket's number fits BvhSortRoom's byte");

static void split_lanes_init(const BvhChildren *children, SplitLanes *lanes)
{
    float on[3][2 * 4] = { { 0 } }, base[2 * 4] = { 0 }, scale[2 * 4] = { 0 },
          last[2 * 4] = { 0 };
    int32_t split_bin[2 * 4] = { 0 };
    for (int s = 1; s < children->count; s++) {
        const BvhSplitTest *t = &children->test[s];
        const uint32_t all = UINT32_MAX;
        memcpy(&on[t->axis][s - 1], &all, sizeof all);
        base[s - 1] = t->base;
        scale[s - 1] = t->scale;
        last[s - 1] = t->last;
        split_bin[s - 1] = t->split_bin;
    }
    for (int h = 0; h < 2; h++) {
        lanes->on_x[h] = _mm_loadu_ps(&on[0][4 * h]);
        lanes->on_y[h] = _mm_loadu_ps(&on[1][4 * h]);
        lanes->on_z[h] = _mm_loadu_ps(&on[2][4 * h]);
        lanes->base[h] = _mm_loadu_ps(&base[4 * h]);
        lanes->scale[h] = _mm_loadu_ps(&scale[4 * h]);
        lanes->last[h] = _mm_loadu_ps(&last[4 * h]);
        lanes->split_bin[h] = _mm_loadu_si128((const __m128i *)&split_bin[4 * h]);
    }
    /* The lanes past count's splits (all 0: bin 0, never past split_bin
     * 0) give bits the table ignores. */
    for (unsigned right = 0; right < sizeof lanes->child; right++) {
        int in = 0;
        for (int s = 1; s < children->count; s++)
            if (in == children->source[s] && (right >> (s - 1) & 1))
                in = s;
        lanes->child[right] = (uint8_t)in;
    }
}

/* The child of lanes' node that prim p goes to: bvh_children4's
 * arithmetic, on one prim in the lanes of all the splits. The eighth lane
 * holds no split (all 0), so its bit is 0 and the table's 128 entries
 * take every outcome. */
static inline int split_lanes_child(const SplitLanes *lanes, const BvhPrim *p)
{
    const __m128 c = _mm_loadu_ps(p->centre);
    const __m128 x = _mm_shuffle_ps(c, c, _MM_SHUFFLE(0, 0, 0, 0)),
                 y = _mm_shuffle_ps(c, c, _MM_SHUFFLE(1, 1, 1, 1)),
                 z = _mm_shuffle_ps(c, c, _MM_SHUFFLE(2, 2, 2, 2));
    int right = 0;
    for (int h = 0; h < 2; h++) {
        const __m128 at = _mm_or_ps(_mm_or_ps(_mm_and_ps(x, lanes->on_x[h]),
                                              _mm_and_ps(y, lanes->on_y[h])),
                                    _mm_and_ps(z, lanes->on_z[h]));
        const __m128i bin = bvh_bins4(at, lanes->base[h], lanes->scale[h], lanes->last[h]);
        right |= _mm_movemask_ps(_mm_castsi128_ps(_mm_cmpgt_epi32(bin, lanes->split_bin[h])))
                 << 4 * h;
    }
    return lanes->child[right];
}

/* The bucket of child k's child g: each child's eight in turn. */
static inline int sort_bucket(int k, int g)
{
    return k * PTR_BVH_WIDTH + g;
}

/* The buckets' counts and boxes, growing with each prim. */
typedef struct BucketBoxes {
    size_t count[SORT_BUCKETS];
    __m128 lower[SORT_BUCKETS], upper[SORT_BUCKETS];
} BucketBoxes;

/* Finds the buckets of the first n (at most 4) of the prims p, in bucket
 * (the children's, or with each child's own splits, own, the
 * grandchildren's), and adds the prims to their buckets' counts and
 * boxes. */
static void add_buckets4(const BvhChildLanes *lanes, const SplitLanes *own, float magnitude,
                         const BvhPrim *p, size_t n, uint8_t *bucket, BucketBoxes *b)
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
        const int k = own ? sort_bucket(four[i], split_lanes_child(&own[four[i]], &p[i]))
                          : four[i];
        __m128 lower, upper;
        bvh_prim_box4(&p[i], magnitude, &lower, &upper);
        b->lower[k] = _mm_min_ps(b->lower[k], lower);
        b->upper[k] = _mm_max_ps(b->upper[k], upper);
        b->count[k]++;
        bucket[i] = (uint8_t)k;
    }
}

PtrResult bvh_sort_room_reserve(BvhSortRoom *room, size_t prims)
{
    if (!room->blocks && !(room->blocks = malloc(SORT_BLOCKS * BVH_SORT_BLOCK *
                                                 sizeof *room->blocks)))
        return PTR_ERR_NOMEM;
    if (room->prims >= prims)
        return PTR_OK;
    free(room->bucket);
    free(room->dest);
    room->bucket = malloc(prims);
    room->dest = malloc((prims / BVH_SORT_BLOCK + 1) * sizeof *room->dest);
    room->prims = room->bucket && room->dest ? prims : 0;
    return room->prims ? PTR_OK : PTR_ERR_NOMEM;
}

void bvh_sort_room_free(BvhSortRoom *room)
{
    free(room->bucket);
    free(room->dest);
    free(room->blocks);
    *room = (BvhSortRoom){ 0 };
}

/* Sorts the n prims p, whose buckets are room->bucket[0 .. n - 1], into
 * them, bucket k's prims to start[k] .. stop[k] - 1 in the order they
 * come, blocks of BVH_SORT_BLOCK prims at a time; count buckets, at most
 * SORT_BUCKETS. (A bucket is called a child below: a node's child, or a
 * child's child.)
 *
 * Block slot t is prims t B .. t B + B - 1. A slot inside a child's places
 * takes a whole block of its prims; the first prims of a child before its
 * first such slot (its head) and the last after its last (its tail) are
 * gathered aside. One pass reads the prims in order: a child's head to its
 * head buffer, then its prims to its block buffer, which when full is
 * written to the next slot, behind the pass (the slots written and the
 * buffers hold every prim read), its child's the slot's tag. The full
 * blocks then go to their slots, each moved once along the chains their
 * slots make (a block whose slot holds another takes its place, that one
 * moving on), and the heads and tails fill the slots the children share. */
static void sort_in_blocks(BvhPrim *p, size_t n, int count, const size_t start[],
                           const size_t stop[], BvhSortRoom *room)
{
    enum { B = BVH_SORT_BLOCK };
    const uint32_t done = UINT32_MAX; /* a slot whose block has moved */
    BvhPrim *fill = room->blocks, *head = fill + SORT_BUCKETS * B,
            *carry = head + SORT_BUCKETS * 2 * B, *spare = carry + B;
    size_t heads[SORT_BUCKETS], first_slot[SORT_BUCKETS], seen[SORT_BUCKETS] = { 0 },
           filled[SORT_BUCKETS] = { 0 }, slots = 0;
    for (int k = 0; k < count; k++) {
        const size_t first = (start[k] + B - 1) / B, last = stop[k] / B;
        /* Without a slot of its own a child is all head: fewer than 2 B
         * prims, which lie in at most two slots. */
        heads[k] = first < last ? first * B - start[k] : stop[k] - start[k];
        first_slot[k] = first;
    }
    uint8_t *child = room->bucket;
    for (size_t i = 0; i < n; i++) {
        const int k = child[i];
        if (seen[k] < heads[k]) {
            head[k * 2 * B + seen[k]++] = p[i];
            continue;
        }
        fill[k * B + filled[k]++] = p[i];
        if (filled[k] == B) {
            /* slots B + B <= i + 1: behind the pass, as is child[slots]. */
            memcpy(&p[slots * B], &fill[k * B], B * sizeof *p);
            child[slots++] = (uint8_t)k;
            filled[k] = 0;
        }
    }
    uint32_t *dest = room->dest;
    size_t next[SORT_BUCKETS];
    for (int k = 0; k < count; k++)
        next[k] = first_slot[k];
    for (size_t t = 0; t < slots; t++)
        dest[t] = (uint32_t)next[child[t]]++;
    for (size_t t = 0; t < slots; t++) {
        if (dest[t] == done)
            continue;
        size_t to = dest[t];
        dest[t] = done;
        if (to == t)
            continue;
        memcpy(carry, &p[t * B], B * sizeof *p);
        /* A slot below slots not yet done holds its block still. */
        while (to < slots && dest[to] != done) {
            memcpy(spare, &p[to * B], B * sizeof *p);
            memcpy(&p[to * B], carry, B * sizeof *p);
            BvhPrim *moved = carry;
            carry = spare;
            spare = moved;
            const size_t on = dest[to];
            dest[to] = done;
            to = on;
        }
        memcpy(&p[to * B], carry, B * sizeof *p);
    }
    for (int k = 0; k < count; k++) {
        memcpy(&p[start[k]], &head[k * 2 * B], heads[k] * sizeof *p);
        if (filled[k])
            memcpy(&p[stop[k] - filled[k]], &fill[k * B], filled[k] * sizeof *p);
    }
}

void bvh_split_children(const BvhPrimSet *set, size_t begin, size_t end, BvhChildren *children,
                        BvhChildren *grandchildren, BvhSortRoom *room)
{
    BvhChildLanes lanes;
    bvh_child_lanes(children, &lanes);
    SplitLanes own[PTR_BVH_WIDTH]; /* each child's splits */
    const int per_child = grandchildren ? PTR_BVH_WIDTH : 1; /* buckets */
    for (int k = 0; grandchildren && k < children->count; k++)
        split_lanes_init(&grandchildren[k], &own[k]);
    BvhPrim *p = set->prims + begin;
    const size_t n = end - begin;
    BucketBoxes b = { .count = { 0 } };
    for (int k = 0; k < children->count * per_child; k++) {
        b.lower[k] = _mm_set1_ps(INFINITY);
        b.upper[k] = _mm_set1_ps(-INFINITY);
    }
    for (size_t i = 0; i < n; i += 4)
        add_buckets4(&lanes, grandchildren ? own : NULL, set->magnitude, &p[i],
                     n - i < 4 ? n - i : 4, &room->bucket[i], &b);
    /* Each child's places, in bvh_children_order's order, and within it,
     * each of its children's in the order of its own. */
    int order[PTR_BVH_WIDTH];
    size_t start[SORT_BUCKETS] = { 0 }, stop[SORT_BUCKETS] = { 0 }, next = 0;
    bvh_children_order(children, order);
    for (int j = 0; j < children->count; j++) {
        const int k = order[j];
        BvhChildren *own_children = grandchildren ? &grandchildren[k] : NULL;
        int own_order[PTR_BVH_WIDTH] = { 0 };
        if (own_children)
            bvh_children_order(own_children, own_order);
        __m128 lower = _mm_set1_ps(INFINITY), upper = _mm_set1_ps(-INFINITY);
        children->begin[k] = begin + next;
        for (int i = 0; i < (own_children ? own_children->count : 1); i++) {
            const int g = own_order[i], at = own_children ? sort_bucket(k, g) : k;
            start[at] = next;
            next += b.count[at];
            stop[at] = next;
            lower = _mm_min_ps(lower, b.lower[at]);
            upper = _mm_max_ps(upper, b.upper[at]);
            if (own_children) {
                own_children->begin[g] = begin + start[at];
                own_children->end[g] = begin + next;
                bvh_store3(own_children->lower[g], b.lower[at]);
                bvh_store3(own_children->upper[g], b.upper[at]);
            }
        }
        children->end[k] = begin + next;
        bvh_store3(children->lower[k], lower);
        bvh_store3(children->upper[k], upper);
    }
    sort_in_blocks(p, n, children->count * per_child, start, stop, room);
}
