#include "accel/bvh_prims.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "base/threads.h"

/* The tree keeps the huge spheres among its own (scene.h's rule) out of its
 * boxes, with a limit of HUGE_RATIO times the median radius: a ground of
 * radius 1000 under spheres of 0.2, or 1e5 under 1, would otherwise make
 * one box span the scene and every ray visit much of the tree. (Spheres the
 * builder chose, against another limit, are tested in double and never
 * reach the tree.) */
enum { HUGE_RATIO = 100 };

/* Pieces the radii are counted and offered in: one a thread, at most this
 * many, and at most one for each RADIUS_PIECE spheres: each piece's
 * counters take 1 MB (see COPIES), which a scene of a few spheres need not
 * clear 16 times. */
enum { RADIUS_PIECES_MAX = 16, RADIUS_PIECE = 1024 };

/* The median radius is found exactly, on all threads, without a copy of
 * the radii: radii are positive finite floats (the importers' rule, and the
 * API's), which order as their bits do, so counting the radii by their high
 * 16 bits finds the median's, and counting those radii by their low 16 bits
 * the rest. A piece's counts fit 32 bits: the build takes fewer than 2^31
 * spheres (TASK_FLAG). */
enum { HALF_BITS = 16, HALF_VALUES = 1 << HALF_BITS };

/* Each half-value is counted in COPIES counters, sphere i in copy i %
 * COPIES, and they are summed after. Equal radii are the common case (a
 * cloud of one size, a molecule's few elements): with one counter each
 * increment waited on the last one's store to the same place. */
enum { COPIES = 4 };

typedef struct RadiusCount {
    const float *radius;
    size_t pieces;
    int low;       /* 0: count by high bits; 1: by low bits, radii with these high bits */
    uint32_t high;
    uint32_t *bins; /* HALF_VALUES * COPIES counters a piece; summed, the first HALF_VALUES */
} RadiusCount;

static void count_radii(void *arg, size_t piece, size_t from, size_t to)
{
    const RadiusCount *c = arg;
    uint32_t *bins = c->bins + piece * HALF_VALUES * COPIES;
    memset(bins, 0, HALF_VALUES * COPIES * sizeof *bins);
    /* In locals: the counters' stores could otherwise change them. */
    const float *radius = c->radius;
    const uint32_t high = c->high;
    if (!c->low)
        for (size_t i = from; i < to; i++) {
            uint32_t bits;
            memcpy(&bits, &radius[i], sizeof bits);
            bins[(bits >> HALF_BITS) * COPIES + i % COPIES]++;
        }
    else
        for (size_t i = from; i < to; i++) {
            uint32_t bits;
            memcpy(&bits, &radius[i], sizeof bits);
            if (bits >> HALF_BITS == high)
                bins[(bits & (HALF_VALUES - 1)) * COPIES + i % COPIES]++;
        }
    /* In place: counter v is written after copies 0 .. COPIES - 1 of
     * half-value v / COPIES <= v are read. */
    for (size_t v = 0; v < HALF_VALUES; v++) {
        uint32_t sum = 0;
        for (size_t k = 0; k < COPIES; k++)
            sum += bins[v * COPIES + k];
        bins[v] = sum;
    }
}

/* The half-value whose radii hold the rank-th (from 0) of those counted,
 * all pieces together; *rank becomes its rank among them. */
static uint32_t half_of_rank(const RadiusCount *c, size_t *rank)
{
    for (uint32_t v = 0;; v++) {
        size_t with_v = 0;
        for (size_t k = 0; k < c->pieces; k++)
            with_v += c->bins[k * HALF_VALUES * COPIES + v];
        if (*rank < with_v)
            return v;
        *rank -= with_v;
    }
}

/* The limit above which a radius is huge for the tree; NaN if out of
 * memory. */
static float huge_radius(const PtrSpheres *s, size_t pieces, int threads)
{
    RadiusCount c = { .radius = s->radius, .pieces = pieces };
    c.bins = malloc(pieces * HALF_VALUES * COPIES * sizeof *c.bins);
    if (!c.bins)
        return NAN;
    size_t rank = s->count / 2;
    ptr_parallel_pieces(threads, s->count, pieces, count_radii, &c);
    c.high = half_of_rank(&c, &rank);
    c.low = 1;
    ptr_parallel_pieces(threads, s->count, pieces, count_radii, &c);
    const uint32_t bits = c.high << HALF_BITS | half_of_rank(&c, &rank);
    free(c.bins);
    float median;
    memcpy(&median, &bits, sizeof median);
    return median * HUGE_RATIO;
}

/* The huge spheres' choice, a piece at a time (ptr_huge_merge joins them). */
typedef struct HugeOffer {
    const PtrSpheres *spheres;
    PtrHugeChoice *choice; /* a piece's, the limit set */
} HugeOffer;

static void offer_huge(void *arg, size_t piece, size_t from, size_t to)
{
    const HugeOffer *o = arg;
    for (size_t i = from; i < to; i++)
        ptr_huge_offer(&o->choice[piece], i, ptr_sphere_id(o->spheres, i), o->spheres->radius[i]);
}

int bvh_rest_by_place(const PtrSpheres *s)
{
    size_t bytes = s->material_size;
#define REST_BYTES(name, type, per_sphere, none, hashed)                                   \
    if (s->name)                                                                           \
        bytes += (per_sphere) * sizeof(type);
    PTR_SPHERE_ATTRIBUTES(REST_BYTES)
#undef REST_BYTES
    return bytes > sizeof(uint64_t);
}

/* The material and attribute arrays of s, whether they exist or not, and
 * the bytes of their entries. */
enum { REST_ARRAYS_MAX = 8 };
#define ONE_MORE(name, type, per_sphere, none, hashed) +1
_Static_assert(1 PTR_SPHERE_ATTRIBUTES(ONE_MORE) <= REST_ARRAYS_MAX, "room for every array");
#undef ONE_MORE

static int rest_arrays(PtrSpheres *s, void **array[REST_ARRAYS_MAX],
                       size_t entry[REST_ARRAYS_MAX])
{
    int n = 0;
    array[n] = &s->material;
    entry[n++] = s->material_size;
#define REST_ARRAY(name, type, per_sphere, none, hashed)                                   \
    array[n] = (void **)&s->name;                                                          \
    entry[n++] = (per_sphere) * sizeof(type);
    PTR_SPHERE_ATTRIBUTES(REST_ARRAY)
#undef REST_ARRAY
    return n;
}

PtrResult bvh_rest_aside(PtrSpheres *s, size_t count, PtrSpheres *aside, PtrError *err)
{
    *aside = (PtrSpheres){ .material_size = s->material_size };
    void **from[REST_ARRAYS_MAX], **to[REST_ARRAYS_MAX];
    size_t entry[REST_ARRAYS_MAX];
    const int n = rest_arrays(s, from, entry);
    rest_arrays(aside, to, entry);
    PtrResult res = PTR_OK;
    for (int k = 0; k < n && res == PTR_OK; k++) {
        if (!*from[k])
            continue;
        *to[k] = *from[k];
        *from[k] = NULL;
        res = ptr_spheres_make(s, from[k], err);
        if (res == PTR_OK)
            memcpy((char *)*from[k] + count * entry[k], (char *)*to[k] + count * entry[k],
                   (s->count - count) * entry[k]);
    }
    if (res != PTR_OK) {
        for (int k = 0; k < n; k++)
            if (*to[k]) {
                free(*from[k]);
                *from[k] = *to[k];
            }
        *aside = (PtrSpheres){ 0 };
    }
    return res;
}

void bvh_rest_free(PtrSpheres *aside)
{
    void **array[REST_ARRAYS_MAX];
    size_t entry[REST_ARRAYS_MAX];
    const int n = rest_arrays(aside, array, entry);
    for (int k = 0; k < n; k++)
        free(*array[k]);
    *aside = (PtrSpheres){ 0 };
}

BvhPrim bvh_prim_geometry(const PtrSpheres *s, size_t i)
{
    return (BvhPrim){ .centre = { s->cx[i], s->cy[i], s->cz[i] }, .radius = s->radius[i] };
}

BvhPrim bvh_prim_of(const PtrSpheres *s, size_t i)
{
    BvhPrim p = bvh_prim_geometry(s, i);
    if (bvh_rest_by_place(s)) {
        p.rest = i;
        return p;
    }
    /* Each shift below 64: the bytes fit (bvh_rest_by_place), and an
     * entry has some. */
    unsigned shift = 8 * (unsigned)s->material_size;
    p.rest = ptr_sphere_material(s, i);
#define PACK(name, type, per_sphere, none, hashed)                                         \
    if (s->name) {                                                                         \
        uint64_t bits = 0;                                                                 \
        memcpy(&bits, &s->name[(per_sphere) * i], (per_sphere) * sizeof(type));            \
        p.rest |= bits << shift;                                                           \
        shift += 8 * (per_sphere) * sizeof(type);                                          \
    }
    PTR_SPHERE_ATTRIBUTES(PACK)
#undef PACK
    return p;
}

void bvh_prim_store(const BvhPrim *p, PtrSpheres *s, size_t i, const PtrSpheres *aside)
{
    s->cx[i] = p->centre[0];
    s->cy[i] = p->centre[1];
    s->cz[i] = p->centre[2];
    s->radius[i] = p->radius;
    if (aside) {
        const size_t from = (size_t)p->rest;
        ptr_sphere_set_material(s, i, ptr_sphere_material(aside, from));
#define GATHER(name, type, per_sphere, none, hashed)                                       \
    if (s->name)                                                                           \
        memcpy(&s->name[(per_sphere) * i], &aside->name[(per_sphere) * from],              \
               (per_sphere) * sizeof(type));
        PTR_SPHERE_ATTRIBUTES(GATHER)
#undef GATHER
        return;
    }
    unsigned shift = 8 * (unsigned)s->material_size;
    ptr_sphere_set_material(s, i, (uint32_t)(p->rest & ((UINT64_C(1) << shift) - 1)));
#define UNPACK(name, type, per_sphere, none, hashed)                                       \
    if (s->name) {                                                                         \
        const uint64_t bits = p->rest >> shift;                                            \
        memcpy(&s->name[(per_sphere) * i], &bits, (per_sphere) * sizeof(type));            \
        shift += 8 * (per_sphere) * sizeof(type);                                          \
    }
    PTR_SPHERE_ATTRIBUTES(UNPACK)
#undef UNPACK
}

PtrResult ptr_bvh_huge(const PtrSpheres *s, int threads, BvhPrim *huge, size_t *huge_index,
                       size_t *huge_count, PtrError *err)
{
    *huge_count = 0;
    if (s->count == 0)
        return PTR_OK;
    size_t pieces = threads < RADIUS_PIECES_MAX ? (size_t)threads : RADIUS_PIECES_MAX;
    if (pieces > 1 + s->count / RADIUS_PIECE)
        pieces = 1 + s->count / RADIUS_PIECE;
    PtrHugeChoice choice = { .limit = huge_radius(s, pieces, threads) };
    if (isnan(choice.limit))
        return bvh_out_of_memory(err);
    PtrHugeChoice piece_choice[RADIUS_PIECES_MAX];
    for (size_t k = 0; k < pieces; k++)
        piece_choice[k] = (PtrHugeChoice){ .limit = choice.limit };
    HugeOffer offer = { s, piece_choice };
    ptr_parallel_pieces(threads, s->count, pieces, offer_huge, &offer);
    ptr_huge_merge(&choice, piece_choice, pieces);
    ptr_huge_file_order(&choice);
    for (size_t k = 0; k < choice.count; k++) {
        huge[k] = bvh_prim_of(s, choice.sphere[k].index);
        size_t at = k;
        for (; at > 0 && huge_index[at - 1] > choice.sphere[k].index; at--)
            huge_index[at] = huge_index[at - 1];
        huge_index[at] = choice.sphere[k].index;
    }
    *huge_count = choice.count;
    return PTR_OK;
}

/* What a sphere adds to the tree's magnitude. */
static float magnitude_of(PtrVec3 centre, float radius)
{
    return v3_max_abs(centre) + radius;
}

static float sphere_magnitude(const PtrSpheres *s, size_t i)
{
    return magnitude_of(ptr_sphere_centre(s, i), s->radius[i]);
}

/* Samples far apart are each a cache miss in every array: fetched this
 * many samples ahead, they overlap. */
enum { SAMPLES_AHEAD = 8 };

typedef struct SampleCopy {
    const PtrSpheres *spheres;
    BvhPrim *samples;
    size_t taken;
} SampleCopy;

/* The sphere sample j of taken is (no overflow: a tree takes fewer than
 * 2^31 spheres, and taken is far below 2^32). */
static size_t sample_sphere(const SampleCopy *c, size_t j)
{
    return j * c->spheres->count / c->taken;
}

static void copy_samples(void *arg, size_t begin, size_t end)
{
    const SampleCopy *c = arg;
    const PtrSpheres *s = c->spheres;
    for (size_t j = begin; j < end; j++) {
        if (end - j > SAMPLES_AHEAD) {
            const size_t i = sample_sphere(c, j + SAMPLES_AHEAD);
            _mm_prefetch((const char *)&s->cx[i], _MM_HINT_T0);
            _mm_prefetch((const char *)&s->cy[i], _MM_HINT_T0);
            _mm_prefetch((const char *)&s->cz[i], _MM_HINT_T0);
            _mm_prefetch((const char *)&s->radius[i], _MM_HINT_T0);
        }
        c->samples[j] = bvh_prim_geometry(s, sample_sphere(c, j));
    }
}

size_t ptr_bvh_samples(const PtrSpheres *s, int threads, const size_t *huge_index,
                       size_t huge_count, BvhPrim *samples, size_t max, float *magnitude)
{
    SampleCopy c = { s, samples, s->count < max ? s->count : max };
    ptr_parallel_ranges(threads, 0, c.taken, copy_samples, &c);
    /* The huge ones left out. */
    size_t count = 0, k = 0;
    *magnitude = 0.0f;
    for (size_t j = 0; j < c.taken; j++) {
        const size_t i = sample_sphere(&c, j);
        while (k < huge_count && huge_index[k] < i)
            k++;
        if (k < huge_count && huge_index[k] == i)
            continue;
        const BvhPrim *p = &samples[j];
        *magnitude = ptr_maxf(magnitude_of(v3(p->centre[0], p->centre[1], p->centre[2]),
                                           p->radius),
                              *magnitude);
        samples[count++] = *p;
    }
    return count;
}

/* The spheres are counted and copied in blocks of this many: a block's
 * prims go to the places its counts, and those of the blocks before it,
 * give them, so the blocks need nothing of each other and the prims' order
 * nothing of the threads. A step of the page bank is whole blocks. */
enum { BLOCK = 1 << 16 };
_Static_assert(PTR_PAGE_STEP % BLOCK == 0, "a page step is whole blocks");

typedef struct RootSort {
    const PtrSpheres *spheres;
    const size_t *huge_index; /* ascending */
    size_t huge_count;
    BvhChildLanes lanes;
    /* Per block: its prims in each child, then, before the copy, the place
     * of its first prim in each; a row more for the children's ends. */
    size_t (*place)[PTR_BVH_WIDTH];
    float *magnitude; /* per block */
    float tree_magnitude; /* the blocks' largest, for the copy's boxes */
    BvhPrim *prims;
    __m128 (*lower)[PTR_BVH_WIDTH], (*upper)[PTR_BVH_WIDTH]; /* per block */
} RootSort;

/* The block's spheres are sorted a chunk at a time: their children first,
 * four at once, then each sphere. */
enum { CHUNK = 1024, NOT_IN_TREE = PTR_BVH_WIDTH };

/* The children of spheres from .. to - 1 (at most CHUNK) in child[i -
 * from], NOT_IN_TREE for the huge ones, four at a time. Lanes past the last
 * sphere read the arrays' padding (PTR_SPHERE_BLOCK entries) into child's
 * last 3 entries. */
static void children_of(const RootSort *r, size_t from, size_t to, uint8_t child[CHUNK + 3])
{
    const PtrSpheres *s = r->spheres;
    for (size_t i = from; i < to; i += 4) {
        const __m128 centre[3] = { _mm_loadu_ps(&s->cx[i]), _mm_loadu_ps(&s->cy[i]),
                                   _mm_loadu_ps(&s->cz[i]) };
        bvh_children4(&r->lanes, centre, &child[i - from]);
    }
    for (size_t k = ptr_huge_before(r->huge_index, r->huge_count, from);
         k < r->huge_count && r->huge_index[k] < to; k++)
        child[r->huge_index[k] - from] = NOT_IN_TREE;
}

/* The end of block b's spheres. */
static size_t block_end(const RootSort *r, size_t b)
{
    return r->spheres->count - b * BLOCK > BLOCK ? (b + 1) * BLOCK : r->spheres->count;
}

/* Counts blocks begin .. end - 1's prims in each child, and their
 * magnitude. */
static void count_blocks(void *arg, size_t begin, size_t end)
{
    RootSort *r = arg;
    const PtrSpheres *s = r->spheres;
    uint8_t child[CHUNK + 3];
    for (size_t b = begin; b < end; b++) {
        size_t *count = r->place[b];
        float magnitude = 0.0f;
        memset(count, 0, PTR_BVH_WIDTH * sizeof *count);
        const size_t end_b = block_end(r, b);
        for (size_t from = b * BLOCK; from < end_b; from += CHUNK) {
            const size_t to = end_b - from > CHUNK ? from + CHUNK : end_b;
            children_of(r, from, to, child);
            for (size_t i = from; i < to; i++)
                if (child[i - from] != NOT_IN_TREE) {
                    count[child[i - from]]++;
                    magnitude = ptr_maxf(sphere_magnitude(s, i), magnitude);
                }
        }
        r->magnitude[b] = magnitude;
    }
}

/* Copies blocks begin .. end - 1's prims to their places, with each
 * child's box of them. */
static void copy_blocks(void *arg, size_t begin, size_t end)
{
    RootSort *r = arg;
    const PtrSpheres *s = r->spheres;
    const float magnitude = r->tree_magnitude;
    uint8_t child[CHUNK + 3];
    for (size_t b = begin; b < end; b++) {
        size_t at[PTR_BVH_WIDTH];
        __m128 *lower = r->lower[b], *upper = r->upper[b];
        memcpy(at, r->place[b], sizeof at);
        for (int k = 0; k < r->lanes.count; k++) {
            lower[k] = _mm_set1_ps(INFINITY);
            upper[k] = _mm_set1_ps(-INFINITY);
        }
        const size_t end_b = block_end(r, b);
        for (size_t from = b * BLOCK; from < end_b; from += CHUNK) {
            const size_t to = end_b - from > CHUNK ? from + CHUNK : end_b;
            children_of(r, from, to, child);
            for (size_t i = from; i < to; i++) {
                const int k = child[i - from];
                if (k == NOT_IN_TREE)
                    continue;
                BvhPrim *p = &r->prims[at[k]++];
                *p = bvh_prim_of(s, i);
                __m128 lo, hi;
                bvh_prim_box4(p, magnitude, &lo, &hi);
                lower[k] = _mm_min_ps(lower[k], lo);
                upper[k] = _mm_max_ps(upper[k], hi);
            }
        }
    }
}

PtrResult ptr_bvh_prims(PtrSpheres *s, int threads, const size_t *huge_index,
                        size_t huge_count, BvhChildren *children, BvhPrim *prims,
                        size_t *prim_count, float *magnitude_out, PtrPageBank *bank,
                        PtrError *err)
{
    *prim_count = s->count - huge_count;
    *magnitude_out = 0.0f;
    for (int k = 0; k < children->count; k++)
        children->begin[k] = children->end[k] = 0;
    const size_t blocks = (s->count + BLOCK - 1) / BLOCK;
    RootSort r = { .spheres = s, .huge_index = huge_index, .huge_count = huge_count,
                   .prims = prims };
    bvh_child_lanes(children, &r.lanes);
    r.place = malloc((blocks + 1) * sizeof *r.place);
    r.magnitude = malloc((blocks ? blocks : 1) * sizeof *r.magnitude);
    r.lower = malloc((blocks ? blocks : 1) * sizeof *r.lower);
    r.upper = malloc((blocks ? blocks : 1) * sizeof *r.upper);
    PtrResult res = r.place && r.magnitude && r.lower && r.upper ? PTR_OK
                                                                 : bvh_out_of_memory(err);
    if (res == PTR_OK && blocks) {
        ptr_parallel_ranges(threads, 0, blocks, count_blocks, &r);
        /* Each child's prims follow those of the child before it in
         * bvh_children_order's order; within a child, each block's follow
         * the block's before. */
        int order[PTR_BVH_WIDTH];
        bvh_children_order(children, order);
        size_t next = 0;
        for (int j = 0; j < children->count; j++) {
            const int k = order[j];
            children->begin[k] = next;
            for (size_t b = 0; b <= blocks; b++) {
                const size_t count = b < blocks ? r.place[b][k] : 0;
                r.place[b][k] = next;
                next += count;
            }
            children->end[k] = next;
        }
        for (size_t b = 0; b < blocks; b++)
            r.tree_magnitude = ptr_maxf(r.magnitude[b], r.tree_magnitude);
        /* Each step's prims on the pages of the spheres the step before
         * copied. */
        const size_t step_blocks = PTR_PAGE_STEP / BLOCK;
        for (size_t first = 0; first < blocks && res == PTR_OK; first += step_blocks) {
            const size_t last = blocks - first > step_blocks ? first + step_blocks : blocks;
            for (int k = 0; k < children->count && res == PTR_OK; k++)
                if (!ptr_pages_take(bank, prims, r.place[first][k] * sizeof *prims,
                                    r.place[last][k] * sizeof *prims))
                    res = bvh_out_of_memory(err);
            if (res != PTR_OK)
                break;
            ptr_parallel_ranges(threads, first, last, copy_blocks, &r);
            const size_t end = last * (size_t)BLOCK < s->count ? last * (size_t)BLOCK : s->count;
            /* The last step's pages stay in the bank, for the write-back's
             * first step, which would fault in as many; what the steps
             * before left goes back, so that the bank holds no more than
             * that while the tree is built. */
            if (end == s->count)
                ptr_pages_free(bank);
            ptr_spheres_release(s, bank, first * (size_t)BLOCK, end);
        }
    }
    if (res == PTR_OK) {
        for (int k = 0; k < children->count; k++) {
            __m128 lower = _mm_set1_ps(INFINITY), upper = _mm_set1_ps(-INFINITY);
            for (size_t b = 0; b < blocks; b++) {
                lower = _mm_min_ps(lower, r.lower[b][k]);
                upper = _mm_max_ps(upper, r.upper[b][k]);
            }
            bvh_store3(children->lower[k], lower);
            bvh_store3(children->upper[k], upper);
        }
        *magnitude_out = r.tree_magnitude;
    }
    free(r.place);
    free(r.magnitude);
    free(r.lower);
    free(r.upper);
    return res;
}

void bvh_child_lanes(const BvhChildren *children, BvhChildLanes *lanes)
{
    lanes->count = children->count;
    for (int k = 1; k < children->count; k++) {
        const BvhSplitTest *t = &children->test[k];
        lanes->axis[k] = t->axis;
        lanes->base[k] = _mm_set1_ps(t->base);
        lanes->scale[k] = _mm_set1_ps(t->scale);
        lanes->last[k] = _mm_set1_ps(t->last);
        lanes->split_bin[k] = _mm_set1_epi32(t->split_bin);
        lanes->source[k] = _mm_set1_epi32(children->source[k]);
    }
}

void bvh_children_order(const BvhChildren *children, int order[PTR_BVH_WIDTH])
{
    order[0] = 0;
    for (int k = 1; k < children->count; k++) {
        int at = k;
        for (; order[at - 1] != children->source[k]; at--)
            order[at] = order[at - 1];
        order[at] = k;
    }
}
