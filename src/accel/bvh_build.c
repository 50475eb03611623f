/* Building the tree: binned SAH splits, eight children a node, leaves of
 * contiguous spheres, the few huge spheres kept out.
 *
 * A node is grown Embree's way: its range is split in two by the binned
 * surface area heuristic, then the child with the largest box is split
 * again, until there are eight children or none has more spheres than a
 * leaf holds. Ranges of up to PTR_BVH_LEAF_MAX spheres are never split: the
 * SIMD leaf test takes 8 spheres in one step, and larger leaves keep the
 * tree small (splitting further by the heuristic doubled the bytes per
 * sphere and did not speed up the C traversal; measured with bench/bvh).
 *
 * Threads: the top of the tree is built on the calling thread, with the
 * binning of large ranges spread over all threads; every
 * subtree of at most task_spheres spheres (1/64 of all, at least
 * TASK_SPHERES_MIN: a rule of the sphere count alone) is a task built by one
 * thread into its own node array. The arrays are then laid out in task
 * order, so the tree's bytes never depend on the number of threads. */
#include "accel/bvh.h"

#include <float.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "accel/bvh_prims.h"
#include "accel/cpu.h"

enum {
    BINS = 32,
    /* From this level on ranges are split in the middle, which bounds the
     * depth by PTR_BVH_MAX_DEPTH whatever the heuristic would do. */
    MIDDLE_SPLIT_LEVEL = PTR_BVH_MAX_DEPTH - 16,
    TASK_SPHERES_MIN = 4096, /* smaller subtrees are never split among tasks */
    TASKS_PER_TREE = 64,     /* about this many tasks, for an even load */
    TASK_FLAG = 1u << 31,    /* a top-level child that is a task, not yet laid out */
};

/* A range of prims being split into a node's children: its box, and the
 * best binned split found for it with the boxes of its two halves. */
typedef struct Candidate {
    size_t begin, end;
    float lower[3], upper[3];
    int axis;         /* of the best split; -1: split in the middle of the range */
    int bins;         /* BINS, fewer for small ranges */
    int split_bin;    /* prims in bins <= split_bin go left */
    float left_lower[3], left_upper[3], right_lower[3], right_upper[3];
    /* Binning: a prim's bin on axis a is (lower + upper - bin_base) * bin_scale,
     * over the candidate's box (cheaper than the box of the centres, which
     * would need a pass of its own, and as good for spheres of similar size). */
    float bin_base[3], bin_scale[3];
} Candidate;

/* Node arrays: the top level's, and one per task. */
typedef struct NodeArray {
    PtrBvhNode *nodes;
    size_t count, capacity;
    int depth;
} NodeArray;

typedef struct Task {
    size_t begin, end;
    int level; /* of its root node */
    NodeArray nodes;
    int failed;
} Task;

typedef struct Build {
    BvhPrim *prims;
    size_t first_sphere; /* position of prims[0] in the reordered arrays */
    size_t task_spheres;
    int threads;
    Task *tasks;
    size_t task_count, task_capacity;
    atomic_size_t next_task;
    int failed;
} Build;

static float half_area(const float lo[3], const float hi[3])
{
    float dx = hi[0] - lo[0], dy = hi[1] - lo[1], dz = hi[2] - lo[2];
    return dx * dy + dy * dz + dz * dx;
}

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

static int bin_of(const Candidate *c, const BvhPrim *p, int axis)
{
    float centre = p->lower[axis] + p->upper[axis];
    /* Clamped as a float, then converted: no branch, and a NaN-free range. */
    float k = (centre - c->bin_base[axis]) * c->bin_scale[axis];
    return (int)ptr_minf(ptr_maxf(k, 0.0f), (float)(c->bins - 1));
}

/* The box only (of a range split in the middle, or of the root). */
static void bound_run(const BvhPrim *prims, size_t begin, size_t end, Bins *b)
{
    for (size_t i = begin; i < end; i++)
        bounds_grow(b->box_lo, b->box_hi, prims[i].lower, prims[i].upper);
}

static void bin_run(const BvhPrim *prims, size_t begin, size_t end, const Candidate *c, Bins *b)
{
    for (size_t i = begin; i < end; i++) {
        const BvhPrim *p = &prims[i];
        for (int a = 0; a < 3; a++) {
            int k = bin_of(c, p, a);
            bounds_grow(b->lower[a][k], b->upper[a][k], p->lower, p->upper);
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
    const Build *build;
    size_t begin, end;
    const Candidate *candidate; /* NULL: bounds only */
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
        bin_run(r->build->prims, lo, hi, r->candidate, r->bins);
    else
        bound_run(r->build->prims, lo, hi, r->bins);
    return NULL;
}

/* Bins (or, with c NULL, only bounds) prims begin .. end - 1 into *out.
 * Counts add and boxes take minima and maxima, so the result does not depend
 * on how the run is shared between threads. Returns 0 if out of memory. */
static int bin_range(const Build *build, size_t begin, size_t end, const Candidate *c, Bins *out)
{
    int threads = end - begin >= PARALLEL_PRIMS ? build->threads : 1;
    int bins = c ? c->bins : 0;
    if (threads == 1) {
        bins_clear(out, bins);
        if (c)
            bin_run(build->prims, begin, end, c, out);
        else
            bound_run(build->prims, begin, end, out);
        return 1;
    }
    Bins *per_thread = malloc((size_t)threads * sizeof *per_thread);
    ParallelRun *runs = malloc((size_t)threads * sizeof *runs);
    pthread_t *ids = malloc((size_t)threads * sizeof *ids);
    if (!per_thread || !runs || !ids) {
        free(per_thread);
        free(runs);
        free(ids);
        return 0;
    }
    int started = 1; /* threads 1 .. started - 1 run; the rest are done here */
    for (int t = 0; t < threads; t++)
        runs[t] = (ParallelRun){ build, begin, end, c, &per_thread[t], t, threads };
    while (started < threads &&
           pthread_create(&ids[started], NULL, parallel_bin_worker, &runs[started]) == 0)
        started++;
    parallel_bin_worker(&runs[0]);
    for (int t = started; t < threads; t++)
        parallel_bin_worker(&runs[t]);
    for (int t = 1; t < started; t++)
        pthread_join(ids[t], NULL);
    bins_clear(out, bins);
    for (int t = 0; t < threads; t++)
        bins_merge(out, &per_thread[t], bins);
    free(per_thread);
    free(runs);
    free(ids);
    return 1;
}

/* Sets c to the range begin .. end - 1 with box lower, upper (NULL: find
 * it) and, if it has more prims than a leaf holds, finds its best split.
 * Returns 0 if out of memory. */
static int candidate_init(const Build *build, Candidate *c, size_t begin, size_t end,
                          const float lower[3], const float upper[3])
{
    Bins bins;
    c->begin = begin;
    c->end = end;
    c->axis = -1;
    if (!lower) {
        if (!bin_range(build, begin, end, NULL, &bins))
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
    if (!bin_range(build, begin, end, c, &bins))
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
            float cost = half_area(lo, hi) * (float)n +
                         half_area(right_lo[k + 1], right_hi[k + 1]) * (float)right_count[k + 1];
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
static size_t partition(const Build *build, const Candidate *c)
{
    size_t begin = c->begin, end = c->end;
    if (c->axis < 0)
        return begin + (end - begin) / 2;
    BvhPrim *p = build->prims;
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

/* Splits c in two (into *left and *right, which may be c). */
static int split(const Build *build, const Candidate *c, int level, Candidate *left,
                 Candidate *right)
{
    Candidate whole = *c;
    if (level >= MIDDLE_SPLIT_LEVEL)
        whole.axis = -1;
    size_t mid = partition(build, &whole);
    if (whole.axis < 0)
        return candidate_init(build, left, whole.begin, mid, NULL, NULL) &&
               candidate_init(build, right, mid, whole.end, NULL, NULL);
    return candidate_init(build, left, whole.begin, mid, whole.left_lower, whole.left_upper) &&
           candidate_init(build, right, mid, whole.end, whole.right_lower, whole.right_upper);
}

static int node_array_add(NodeArray *a, size_t *index)
{
    if (a->count == a->capacity) {
        size_t capacity = a->capacity ? a->capacity * 2 : 64;
        PtrBvhNode *grown = aligned_alloc(64, capacity * sizeof *grown);
        if (!grown)
            return 0;
        if (a->count)
            memcpy(grown, a->nodes, a->count * sizeof *grown);
        free(a->nodes);
        a->nodes = grown;
        a->capacity = capacity;
    }
    *index = a->count++;
    return 1;
}

static int add_task(Build *build, size_t begin, size_t end, int level, uint32_t *task)
{
    if (build->task_count == build->task_capacity) {
        size_t capacity = build->task_capacity ? build->task_capacity * 2 : 64;
        Task *grown = realloc(build->tasks, capacity * sizeof *grown);
        if (!grown)
            return 0;
        build->tasks = grown;
        build->task_capacity = capacity;
    }
    *task = (uint32_t)build->task_count;
    build->tasks[build->task_count++] = (Task){ .begin = begin, .end = end, .level = level };
    return 1;
}

/* Builds the node at this level over c's range into nodes (its index in
 * *index), and its inner children below it; depth: levels below the node. In
 * the top level (top set), inner children of at most task_spheres spheres
 * become tasks. */
static int build_node(Build *build, NodeArray *nodes, const Candidate *range, int top,
                      int level, size_t *index, int *depth)
{
    Candidate child[PTR_BVH_WIDTH];
    int n = 1;
    child[0] = *range;
    for (; n < PTR_BVH_WIDTH; n++) {
        int pick = -1;
        float pick_area = -1.0f;
        for (int k = 0; k < n; k++) {
            float area = half_area(child[k].lower, child[k].upper);
            if (child[k].end - child[k].begin > PTR_BVH_LEAF_MAX && area > pick_area) {
                pick = k;
                pick_area = area;
            }
        }
        if (pick < 0)
            break;
        if (!split(build, &child[pick], level, &child[pick], &child[n]))
            return 0;
    }

    if (!node_array_add(nodes, index))
        return 0;
    size_t self = *index;
    PtrBvhNode node;
    *depth = 0;
    for (int k = 0; k < PTR_BVH_WIDTH; k++) {
        if (k >= n) {
            node.lower_x[k] = node.lower_y[k] = node.lower_z[k] = INFINITY;
            node.upper_x[k] = node.upper_y[k] = node.upper_z[k] = -INFINITY;
            node.child[k] = 0;
            node.leaf_count[k] = 0;
            continue;
        }
        const Candidate *c = &child[k];
        node.lower_x[k] = c->lower[0];
        node.lower_y[k] = c->lower[1];
        node.lower_z[k] = c->lower[2];
        node.upper_x[k] = c->upper[0];
        node.upper_y[k] = c->upper[1];
        node.upper_z[k] = c->upper[2];
        size_t count = c->end - c->begin;
        if (count <= PTR_BVH_LEAF_MAX) {
            ptr_bvh_sort_leaf(build->prims + c->begin, count);
            node.child[k] = (uint32_t)(build->first_sphere + c->begin);
            node.leaf_count[k] = (uint32_t)count;
            continue;
        }
        node.leaf_count[k] = 0;
        if (top && count <= build->task_spheres) {
            uint32_t task;
            if (!add_task(build, c->begin, c->end, level + 1, &task))
                return 0;
            node.child[k] = TASK_FLAG | task;
            continue;
        }
        size_t below;
        int below_depth;
        if (!build_node(build, nodes, c, top, level + 1, &below, &below_depth))
            return 0;
        node.child[k] = (uint32_t)below;
        if (below_depth + 1 > *depth)
            *depth = below_depth + 1;
    }
    nodes->nodes[self] = node; /* after the children: the array may have moved */
    return 1;
}

static void *task_worker(void *arg)
{
    Build *build = arg;
    for (;;) {
        size_t i = atomic_fetch_add(&build->next_task, 1);
        if (i >= build->task_count)
            return NULL;
        Task *t = &build->tasks[i];
        Candidate range;
        size_t root;
        t->failed = !candidate_init(build, &range, t->begin, t->end, NULL, NULL) ||
                    !build_node(build, &t->nodes, &range, 0, t->level, &root, &t->nodes.depth);
    }
}

static int run_tasks(Build *build)
{
    int threads = build->threads;
    pthread_t *ids = malloc((size_t)threads * sizeof *ids);
    if (!ids)
        return 0;
    atomic_init(&build->next_task, 0);
    int started = 0;
    while (started < threads - 1 && pthread_create(&ids[started], NULL, task_worker, build) == 0)
        started++;
    task_worker(build);
    for (int i = 0; i < started; i++)
        pthread_join(ids[i], NULL);
    free(ids);
    for (size_t i = 0; i < build->task_count; i++)
        if (build->tasks[i].failed)
            return 0;
    return 1;
}

/* One node array: the top level's first, then each task's, with every task
 * reference and every inner child index moved to its final place. */
static int lay_out(Build *build, NodeArray *top, PtrBvh *bvh)
{
    size_t total = top->count;
    for (size_t i = 0; i < build->task_count; i++)
        total += build->tasks[i].nodes.count;
    PtrBvhNode *nodes = aligned_alloc(64, total * sizeof *nodes);
    if (!nodes)
        return 0;
    memcpy(nodes, top->nodes, top->count * sizeof *nodes);
    size_t *start = malloc((build->task_count + 1) * sizeof *start);
    if (!start) {
        free(nodes);
        return 0;
    }
    size_t at = top->count;
    for (size_t i = 0; i < build->task_count; i++) {
        const NodeArray *a = &build->tasks[i].nodes;
        start[i] = at;
        memcpy(nodes + at, a->nodes, a->count * sizeof *nodes);
        for (size_t j = at; j < at + a->count; j++)
            for (int k = 0; k < PTR_BVH_WIDTH; k++)
                if (nodes[j].leaf_count[k] == 0 && nodes[j].lower_x[k] <= nodes[j].upper_x[k])
                    nodes[j].child[k] += (uint32_t)at;
        at += a->count;
    }
    /* The depth of the top level counts a task as one level; add the rest. */
    int depth = 0;
    for (size_t j = 0; j < top->count; j++)
        for (int k = 0; k < PTR_BVH_WIDTH; k++)
            if (nodes[j].leaf_count[k] == 0 && (nodes[j].child[k] & TASK_FLAG) &&
                nodes[j].lower_x[k] <= nodes[j].upper_x[k]) {
                const Task *t = &build->tasks[nodes[j].child[k] & ~TASK_FLAG];
                nodes[j].child[k] = (uint32_t)start[t - build->tasks];
                if (t->nodes.depth > depth)
                    depth = t->nodes.depth;
            }
    free(start);
    bvh->nodes = nodes;
    bvh->node_count = total;
    bvh->depth = top->depth + 1 + depth;
    return 1;
}

PtrResult ptr_bvh_build(PtrBvh *bvh, PtrSpheres *spheres, int threads)
{
    memset(bvh, 0, sizeof *bvh);
    size_t count = spheres->count;
    if (count >= TASK_FLAG)
        return PTR_ERR_NOMEM;
    uint32_t *order = malloc((count ? count : 1) * sizeof *order);
    Build build = { .threads = threads > 0 ? threads : ptr_online_cpus() };
    build.prims = malloc((count ? count : 1) * sizeof *build.prims);
    NodeArray top = { 0 };
    int ok = order && build.prims;
    size_t prim_count = 0;
    if (ok)
        ok = ptr_bvh_prims(spheres, order, &bvh->unbounded_count, build.prims, &prim_count);
    build.first_sphere = bvh->unbounded_count;
    build.task_spheres = prim_count / TASKS_PER_TREE > TASK_SPHERES_MIN
                             ? prim_count / TASKS_PER_TREE : TASK_SPHERES_MIN;
    if (ok && prim_count > 0) {
        Candidate root;
        size_t index;
        ok = candidate_init(&build, &root, 0, prim_count, NULL, NULL) &&
             build_node(&build, &top, &root, 1, 0, &index, &top.depth) && run_tasks(&build) &&
             lay_out(&build, &top, bvh);
    }
    if (ok) {
        for (size_t i = 0; i < prim_count; i++)
            order[bvh->unbounded_count + i] = build.prims[i].index;
        ok = ptr_spheres_permute(spheres, order) == PTR_OK;
    }
    for (size_t i = 0; i < build.task_count; i++)
        free(build.tasks[i].nodes.nodes);
    free(build.tasks);
    free(top.nodes);
    free(build.prims);
    free(order);
    if (!ok) {
        ptr_bvh_free(bvh);
        return PTR_ERR_NOMEM;
    }
    return PTR_OK;
}

void ptr_bvh_free(PtrBvh *bvh)
{
    free(bvh->nodes);
    memset(bvh, 0, sizeof *bvh);
}
