#include "accel/bvh_prims.h"

#include <math.h>
#include <stdatomic.h>
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

BvhPrim bvh_prim_of(const PtrSpheres *s, size_t i)
{
    BvhPrim p = { .centre = { s->cx[i], s->cy[i], s->cz[i] }, .radius = s->radius[i],
                  .id = ptr_sphere_id(s, i), .material = ptr_sphere_material(s, i) };
#define COPY_IN(name, type, per_sphere, none)                                              \
    if (s->name)                                                                           \
        memcpy(p.name, &s->name[(per_sphere) * i], sizeof p.name);
    PTR_SPHERE_ATTRIBUTES(COPY_IN)
#undef COPY_IN
    return p;
}

void bvh_prim_store(const BvhPrim *p, PtrSpheres *s, size_t i)
{
    s->cx[i] = p->centre[0];
    s->cy[i] = p->centre[1];
    s->cz[i] = p->centre[2];
    s->radius[i] = p->radius;
    ptr_sphere_set_material(s, i, p->material);
#define COPY_OUT(name, type, per_sphere, none)                                             \
    if (s->name)                                                                           \
        memcpy(&s->name[(per_sphere) * i], p->name, sizeof p->name);
    PTR_SPHERE_ATTRIBUTES(COPY_OUT)
#undef COPY_OUT
}

/* The copy of spheres into prims, in pieces on all threads: a piece's first
 * prim is its first sphere's index less the huge spheres before it, so the
 * pieces need nothing of each other. */
typedef struct PrimCopy {
    const PtrSpheres *spheres;
    BvhPrim *prims;
    const size_t *huge_index; /* ascending */
    size_t huge_count;
    /* The largest magnitude so far, as the bits of a float that is never
     * negative: such floats order as their bits do. */
    atomic_uint_least32_t magnitude;
} PrimCopy;

static void copy_prims(void *arg, size_t begin, size_t end)
{
    PrimCopy *c = arg;
    size_t k = ptr_huge_before(c->huge_index, c->huge_count, begin);
    BvhPrim *out = c->prims + (begin - k);
    float magnitude = 0.0f;
    for (size_t i = begin; i < end; i++) {
        if (k < c->huge_count && c->huge_index[k] == i) {
            k++;
            continue;
        }
        const float m = v3_max_abs(ptr_sphere_centre(c->spheres, i)) + c->spheres->radius[i];
        if (m > magnitude)
            magnitude = m;
        *out++ = bvh_prim_of(c->spheres, i);
    }
    uint32_t bits;
    memcpy(&bits, &magnitude, sizeof bits);
    uint_least32_t seen = atomic_load(&c->magnitude);
    while (bits > seen && !atomic_compare_exchange_weak(&c->magnitude, &seen, bits))
        ;
}

PtrResult ptr_bvh_prims(PtrSpheres *s, int threads, BvhPrim *huge, size_t *huge_count,
                        BvhPrim *prims, size_t *prim_count, float *magnitude_out, PtrError *err)
{
    *huge_count = *prim_count = 0;
    *magnitude_out = 0.0f;
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
    /* By index, to skip them below. */
    size_t out[PTR_HUGE_MAX];
    for (size_t k = 0; k < choice.count; k++) {
        huge[k] = bvh_prim_of(s, choice.sphere[k].index);
        size_t at = k;
        for (; at > 0 && out[at - 1] > choice.sphere[k].index; at--)
            out[at] = out[at - 1];
        out[at] = choice.sphere[k].index;
    }
    PrimCopy copy = { .spheres = s, .prims = prims, .huge_index = out,
                      .huge_count = choice.count };
    atomic_init(&copy.magnitude, 0);
    /* Each step's prims on the pages of the spheres the step before
     * copied. */
    PtrPageBank bank = { 0 };
    size_t first_prim = 0;
    for (size_t begin = 0; begin < s->count; begin += PTR_PAGE_STEP) {
        const size_t end = s->count - begin > PTR_PAGE_STEP ? begin + PTR_PAGE_STEP : s->count;
        const size_t end_prim = end - ptr_huge_before(out, choice.count, end);
        if (!ptr_pages_take(&bank, prims, first_prim * sizeof *prims, end_prim * sizeof *prims)) {
            ptr_pages_free(&bank);
            return bvh_out_of_memory(err);
        }
        ptr_parallel_ranges(threads, begin, end, copy_prims, &copy);
        ptr_spheres_release(s, end < s->count ? &bank : NULL, begin, end);
        first_prim = end_prim;
    }
    ptr_pages_free(&bank);
    const uint32_t bits = (uint32_t)atomic_load(&copy.magnitude);
    memcpy(magnitude_out, &bits, sizeof bits);
    *huge_count = choice.count;
    *prim_count = s->count - choice.count;
    return PTR_OK;
}

void ptr_bvh_sort_leaf(BvhPrim *prims, size_t count)
{
    for (size_t i = 1; i < count; i++) {
        BvhPrim v = prims[i];
        size_t j = i;
        for (; j > 0 && prims[j - 1].id > v.id; j--)
            prims[j] = prims[j - 1];
        prims[j] = v;
    }
}
