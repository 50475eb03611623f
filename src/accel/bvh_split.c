#include "accel/bvh_split.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/threads.h"

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
 * box. */
typedef struct Bins {
    float lower[3][BINS][3], upper[3][BINS][3];
    size_t count[3][BINS];
    float box_lo[3], box_hi[3];
} Bins;

static void bins_clear(Bins *b, int bins)
{
    for (int a = 0; a < 3; a++)
        for (int k = 0; k < bins; k++) {
            bounds_empty(b->lower[a][k], b->upper[a][k]);
            b->count[a][k] = 0;
        }
    bounds_empty(b->box_lo, b->box_hi);
}

static int bin_of(const BvhCandidate *c, const BvhPrim *p, int axis)
{
    /* Twice the centre, as the box gives it. */
    float centre = (p->centre[axis] - p->extent) + (p->centre[axis] + p->extent);
    /* Clamped as a float, then converted: no branch, and a NaN-free range. */
    float k = (centre - c->bin_base[axis]) * c->bin_scale[axis];
    return (int)ptr_minf(ptr_maxf(k, 0.0f), (float)(c->bins - 1));
}

/* The box only (of a range split in the middle, or of the root). */
static void bound_run(const BvhPrim *prims, size_t begin, size_t end, Bins *b)
{
    for (size_t i = begin; i < end; i++) {
        float lower[3], upper[3];
        bvh_prim_box(&prims[i], lower, upper);
        bounds_grow(b->box_lo, b->box_hi, lower, upper);
    }
}

static void bin_run(const BvhPrim *prims, size_t begin, size_t end, const BvhCandidate *c, Bins *b)
{
    for (size_t i = begin; i < end; i++) {
        const BvhPrim *p = &prims[i];
        float lower[3], upper[3];
        bvh_prim_box(p, lower, upper);
        for (int a = 0; a < 3; a++) {
            int k = bin_of(c, p, a);
            bounds_grow(b->lower[a][k], b->upper[a][k], lower, upper);
            b->count[a][k]++;
        }
    }
}

static void bins_merge(Bins *into, const Bins *b, int bins)
{
    for (int a = 0; a < 3; a++)
        for (int k = 0; k < bins; k++) {
            bounds_grow(into->lower[a][k], into->upper[a][k], b->lower[a][k], b->upper[a][k]);
            into->count[a][k] += b->count[a][k];
        }
    bounds_grow(into->box_lo, into->box_hi, b->box_lo, b->box_hi);
}

/* Runs of this many prims are bounded, binned and partitioned by all threads
 * together; smaller ones by the calling thread. */
enum { PARALLEL_PRIMS = 1 << 16 };

typedef struct ParallelRun {
    const BvhPrimSet *set;
    size_t begin, end;
    const BvhCandidate *candidate; /* NULL: bounds only */
    Bins *bins;                 /* one per thread */
    int thread, threads;
} ParallelRun;

static void *parallel_bin_worker(void *arg)
{
    ParallelRun *r = arg;
    size_t n = r->end - r->begin;
    size_t lo = r->begin + n * (size_t)r->thread / (size_t)r->threads;
    size_t hi = r->begin + n * (size_t)(r->thread + 1) / (size_t)r->threads;
    bins_clear(r->bins, r->candidate ? r->candidate->bins : 0);
    if (r->candidate)
        bin_run(r->set->prims, lo, hi, r->candidate, r->bins);
    else
        bound_run(r->set->prims, lo, hi, r->bins);
    return NULL;
}

/* Bins (or, with c NULL, only bounds) prims begin .. end - 1 into *out.
 * Counts add and boxes take minima and maxima, so the result does not depend
 * on how the run is shared between threads. Returns 0 if out of memory. */
static int bin_range(const BvhPrimSet *set, size_t begin, size_t end, const BvhCandidate *c, Bins *out)
{
    int threads = end - begin >= PARALLEL_PRIMS ? set->threads : 1;
    int bins = c ? c->bins : 0;
    if (threads == 1) {
        bins_clear(out, bins);
        if (c)
            bin_run(set->prims, begin, end, c, out);
        else
            bound_run(set->prims, begin, end, out);
        return 1;
    }
    Bins *per_thread = malloc((size_t)threads * sizeof *per_thread);
    ParallelRun *runs = malloc((size_t)threads * sizeof *runs);
    PtrThread **ids = malloc((size_t)threads * sizeof *ids);
    if (!per_thread || !runs || !ids) {
        free(per_thread);
        free(runs);
        free(ids);
        return 0;
    }
    int started = 1; /* threads 1 .. started - 1 run; the rest are done here */
    for (int t = 0; t < threads; t++)
        runs[t] = (ParallelRun){ set, begin, end, c, &per_thread[t], t, threads };
    while (started < threads && (ids[started] = ptr_thread_start(parallel_bin_worker, &runs[started])))
        started++;
    parallel_bin_worker(&runs[0]);
    for (int t = started; t < threads; t++)
        parallel_bin_worker(&runs[t]);
    for (int t = 1; t < started; t++)
        ptr_thread_join(ids[t]);
    bins_clear(out, bins);
    for (int t = 0; t < threads; t++)
        bins_merge(out, &per_thread[t], bins);
    free(per_thread);
    free(runs);
    free(ids);
    return 1;
}

int bvh_candidate_init(const BvhPrimSet *set, BvhCandidate *c, size_t begin, size_t end,
                          const float lower[3], const float upper[3])
{
    Bins bins;
    c->begin = begin;
    c->end = end;
    c->axis = -1;
    if (!lower) {
        if (!bin_range(set, begin, end, NULL, &bins))
            return 0;
        lower = bins.box_lo;
        upper = bins.box_hi;
    }
    memcpy(c->lower, lower, sizeof c->lower);
    memcpy(c->upper, upper, sizeof c->upper);
    if (end - begin <= PTR_BVH_LEAF_MAX)
        return 1;
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
        return 1;
    if (!bin_range(set, begin, end, c, &bins))
        return 0;
    float best = INFINITY;
    for (int a = 0; a < 3; a++) {
        float right_lo[BINS][3], right_hi[BINS][3];
        size_t right_count[BINS];
        float lo[3], hi[3];
        bounds_empty(lo, hi);
        size_t n = 0;
        for (int k = c->bins - 1; k > 0; k--) {
            bounds_grow(lo, hi, bins.lower[a][k], bins.upper[a][k]);
            n += bins.count[a][k];
            memcpy(right_lo[k], lo, sizeof lo);
            memcpy(right_hi[k], hi, sizeof hi);
            right_count[k] = n;
        }
        bounds_empty(lo, hi);
        n = 0;
        for (int k = 0; k < c->bins - 1; k++) {
            bounds_grow(lo, hi, bins.lower[a][k], bins.upper[a][k]);
            n += bins.count[a][k];
            if (n == 0 || right_count[k + 1] == 0)
                continue;
            float cost = bvh_half_area(lo, hi) * (float)n +
                         bvh_half_area(right_lo[k + 1], right_hi[k + 1]) * (float)right_count[k + 1];
            if (cost < best) {
                best = cost;
                c->axis = a;
                c->split_bin = k;
                memcpy(c->left_lower, lo, sizeof lo);
                memcpy(c->left_upper, hi, sizeof hi);
                memcpy(c->right_lower, right_lo[k + 1], sizeof lo);
                memcpy(c->right_upper, right_hi[k + 1], sizeof hi);
            }
        }
    }
    return 1;
}

/* Moves the prims of c that go left before those that go right; returns
 * the first right one. Hoare's partition: deterministic for a given input. */
static size_t partition(const BvhPrimSet *set, const BvhCandidate *c)
{
    size_t begin = c->begin, end = c->end;
    if (c->axis < 0)
        return begin + (end - begin) / 2;
    BvhPrim *p = set->prims;
    size_t i = begin, j = end;
    for (;;) {
        while (i < j && bin_of(c, &p[i], c->axis) <= c->split_bin)
            i++;
        while (i < j && bin_of(c, &p[j - 1], c->axis) > c->split_bin)
            j--;
        if (i >= j)
            return i;
        BvhPrim t = p[i];
        p[i] = p[j - 1];
        p[j - 1] = t;
        i++;
        j--;
    }
}

int bvh_split(const BvhPrimSet *set, const BvhCandidate *c, int middle, BvhCandidate *left,
              BvhCandidate *right)
{
    BvhCandidate whole = *c;
    if (middle)
        whole.axis = -1;
    size_t mid = partition(set, &whole);
    if (whole.axis < 0)
        return bvh_candidate_init(set, left, whole.begin, mid, NULL, NULL) &&
               bvh_candidate_init(set, right, mid, whole.end, NULL, NULL);
    return bvh_candidate_init(set, left, whole.begin, mid, whole.left_lower, whole.left_upper) &&
           bvh_candidate_init(set, right, mid, whole.end, whole.right_lower, whole.right_upper);
}
