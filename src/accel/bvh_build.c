/* Building the tree: binned SAH splits, eight children a node, leaves of
 * contiguous spheres, the few huge spheres kept out of the boxes.
 *
 * A node is grown Embree's way: its range is split in two by the binned
 * surface area heuristic, then the child with the largest box is split
 * again, until there are eight children or none has more spheres than a
 * leaf holds. Ranges of up to PTR_BVH_LEAF_MAX (16) spheres are never
 * split: the SIMD leaf test takes 8 spheres a step, and larger leaves keep
 * the tree small (a first version that split by the heuristic down to single
 * spheres had three times the bytes a sphere and traced 1.3 to 1.6 times
 * slower in C; measured with bench/bvh).
 *
 * A node over more than BOTTOM_SPHERES spheres leaves any child of at most
 * that many unsplit: it becomes a node of its own, whose leaves then fill
 * most of its lanes. Split there too, it would be cut into eighths that
 * each took a node for two or three leaves: so, with leaves of up to 8,
 * bench/bvh's 10^6-sphere cloud took 9.6 bytes a sphere in nodes; with
 * leaves of 16 and this rule, 5.4, at the same rays per second
 * (docs/intersectors.md, "Full nodes at the bottom").
 *
 * The root is grown so too, but from samples of the spheres before the
 * prims exist (plan_root): the copy that makes the prims then sorts them
 * into the root's children (ptr_bvh_prims), on all threads, in the pass
 * it makes anyway. Split in place, the root's ranges took a pass over every
 * prim for their box and one for each level of its splits, about three,
 * which streamed memory at 1.8x on two threads (docs/intersectors.md, "The
 * root chosen before the copy"). Every node of more than BVH_PLANNED_ABOVE
 * prims is grown so from samples of its prims, which are then sorted into
 * its children in place (plan_node); a child that the node's samples put
 * over BVH_PLANNED_ABOVE is planned with it, and the prims sorted into its
 * children in the same pass (plan_below).
 *
 * Threads: each of the root's children of more than task_spheres spheres
 * (1/64 of all, at least TASK_SPHERES_MIN: a rule of the sphere count
 * alone) is a part: the rest of the top level below it, built by one thread
 * into its own node and task arrays, while the other threads build other
 * parts. (When every split of the top level was shared, each of some 300
 * at 10^6 handing work to the others and back, the top level gained 1.2x
 * from a second thread.) Every subtree of at most task_spheres spheres is
 * a task built by one thread into its own node array. The threads take the
 * parts, then the tasks, from one pool (see Pool). The arrays are laid out
 * in the order a depth-first build on one thread would have made them, so
 * the tree's bytes never depend on the number of threads. */
#include "accel/bvh.h"

#include <malloc.h>
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "accel/bvh_prims.h"
#include "accel/bvh_split.h"
#include "base/cpu.h"
#include "base/memory.h"
#include "base/threads.h"

enum {
    /* From this level on ranges are split in the middle, which bounds the
     * depth by PTR_BVH_MAX_DEPTH whatever the heuristic would do. */
    MIDDLE_SPLIT_LEVEL = PTR_BVH_MAX_DEPTH - 16,
    TASK_SPHERES_MIN = 4096, /* smaller subtrees are never split among tasks */
    TASKS_PER_TREE = 64,     /* about this many tasks, for an even load */
    TASK_FLAG = 1u << 31,    /* a top-level child that is a task, not yet laid out */
    PART_FLAG = 1u << 30,    /* a child of the root that is a part, not yet laid out */
    /* See the head: 6 leaves' worth (7 or 5 gave 0.2 and 0.05 bytes a sphere
     * more on a uniform 10^6 cloud). */
    BOTTOM_SPHERES = 6 * PTR_BVH_LEAF_MAX,
    PLAN_SAMPLES = 1 << 15, /* see plan_children */
    PLAN_SHARE = 16,        /* a planned node samples one prim in this many: see plan_node */
    PLAN_AHEAD = 64,        /* samples fetched ahead: see take_samples */
    PRIMS_A_NODE = 32,      /* a task's first node array: see build_task */
};

/* Node arrays: the root's, one per part and one per task. */
typedef struct NodeArray {
    PtrBvhNode *nodes;
    size_t count, capacity;
    int depth;
} NodeArray;

typedef struct Task {
    /* Its prims, their box and their split, found where the task was made
     * but for the root's children, which ptr_bvh_build gives their boxes
     * only (split_found 0): the task's thread finds theirs. */
    BvhCandidate range;
    int split_found;
    /* Its prims sorted into its root's children where the node above
     * planned them too (count above 1, see plan_below), else none. */
    BvhChildren presorted;
    int level; /* of its root node */
    NodeArray nodes;
} Task;

typedef struct TaskList {
    Task *tasks;
    size_t count, capacity;
} TaskList;

/* A part of the top level: a child of the root and the top level below it,
 * whose tasks are its own until join_parts numbers them all. */
typedef struct Part {
    BvhCandidate range;
    int level; /* of its root node */
    NodeArray nodes;
    TaskList tasks;
} Part;

/* How make_node treats a node: the root makes parts of its large children;
 * a node of a part makes tasks of its small children (both: its children of
 * at most task_spheres); a node of a task splits on. */
typedef enum NodeKind { NODE_ROOT, NODE_PART, NODE_TASK } NodeKind;

/* The parts and tasks the threads share once the root is built: the parts
 * first, largest first, then the tasks, the largest ready one first. A
 * part's tasks are ready once the part is built, so that a thread waits for
 * the last parts only when no task is ready (with one phase for the parts
 * and one for the tasks, a thread of two sat idle for a tenth of the parts'
 * time at 10^7 spheres), and the largest tasks do not come last. */
typedef struct Pool {
    struct Build *build;
    pthread_mutex_t lock;
    /* A part is built or has failed: its tasks are ready, one part fewer
     * is running. */
    pthread_cond_t wake;
    size_t part_order[PTR_BVH_WIDTH]; /* the parts, largest first, for an even load */
    size_t next_part;     /* in part_order */
    size_t parts_running; /* taken and not yet built */
    Task **ready;         /* a heap, the largest task first */
    size_t ready_count, ready_capacity;
    int failed;           /* out of memory: take no more */
} Pool;

typedef struct Build {
    BvhPrimSet set;
    /* The build's threads: all of them make the prims (ptr_bvh_prims); a
     * part or a task, run on one of them while the others run theirs,
     * splits on its thread alone. */
    int threads;
    size_t first_sphere; /* position of prims[0] in the reordered arrays */
    size_t task_spheres;
    TaskList root_tasks; /* the root's small children */
    Part parts[PTR_BVH_WIDTH]; /* its large ones */
    size_t part_count;
    TaskList tasks;           /* all, in the order of a depth-first build */
} Build;

/* What a thread of the build keeps from one part or task to the next: fresh
 * memory for each would be cleared page by page. */
typedef struct Worker {
    BvhPrim *scratch; /* room for BVH_PLANNED_ABOVE: see bvh_split */
    BvhPrim *samples; /* room for PTR_BVH_WIDTH PLAN_SAMPLES: see plan_below */
    BvhSortRoom sort; /* for the largest range planned */
} Worker;

/* The build's prims set, over other prims (a node's samples): the same
 * magnitude and binning. */
static BvhPrimSet set_over(const Build *build, BvhPrim *prims)
{
    BvhPrimSet set = build->set;
    set.prims = prims;
    return set;
}

/* A thread's scratch and samples, made for its first node: whether there
 * is memory for them. */
static int worker_ready(Worker *w)
{
    if (!w->scratch)
        w->scratch = malloc(BVH_PLANNED_ABOVE * sizeof *w->scratch);
    if (!w->samples)
        w->samples = malloc(PTR_BVH_WIDTH * PLAN_SAMPLES * sizeof *w->samples);
    return w->scratch && w->samples;
}

/* Gives a room for capacity nodes, its nodes kept; whether there was
 * memory. */
static int node_array_grow(NodeArray *a, size_t capacity)
{
    PtrBvhNode *grown = aligned_alloc(64, capacity * sizeof *grown);
    if (!grown)
        return 0;
    if (a->count)
        memcpy(grown, a->nodes, a->count * sizeof *grown);
    free(a->nodes);
    a->nodes = grown;
    a->capacity = capacity;
    return 1;
}

/* A new node at the end of a, its index in *index. */
static PtrResult node_array_add(NodeArray *a, size_t *index, PtrError *err)
{
    if (a->count == a->capacity && !node_array_grow(a, a->capacity ? a->capacity * 2 : 64))
        return bvh_out_of_memory(err);
    *index = a->count++;
    return PTR_OK;
}

static PtrResult add_task(TaskList *list, const BvhCandidate *range, int split_found,
                          const BvhChildren *presorted, int level, uint32_t *task,
                          PtrError *err)
{
    if (list->count == list->capacity) {
        size_t capacity = list->capacity ? list->capacity * 2 : 64;
        Task *grown = realloc(list->tasks, capacity * sizeof *grown);
        if (!grown)
            return bvh_out_of_memory(err);
        list->tasks = grown;
        list->capacity = capacity;
    }
    *task = (uint32_t)list->count;
    list->tasks[list->count++] = (Task){ .range = *range, .split_found = split_found,
                                         .presorted = presorted ? *presorted
                                                                : (BvhChildren){ 0 },
                                         .level = level };
    return PTR_OK;
}

/* Splits range, at this level, into a node's children, child[0 .. *count -
 * 1], Embree's way (see the head). Each prim of range stands for per_prim
 * of the tree's (1 but for samples, see plan_children), in the
 * counts that decide which children are split. With plan, each split is
 * recorded in it, and a child is split only by its best split, against
 * which a prim can be tested (bvh_split_test), never in the middle.
 * scratch: room for BVH_PLANNED_ABOVE prims, see bvh_split. */
static void grow_node(const BvhPrimSet *set, BvhPrim *scratch, const BvhCandidate *range,
                      int level, double per_prim, BvhCandidate child[PTR_BVH_WIDTH],
                      int *count, BvhChildren *plan)
{
    int n = 1;
    child[0] = *range;
    const int over_bottom = (double)(range->end - range->begin) * per_prim > BOTTOM_SPHERES;
    for (; n < PTR_BVH_WIDTH; n++) {
        int pick = -1;
        float pick_area = -1.0f;
        for (int k = 0; k < n; k++) {
            float area = bvh_half_area(child[k].lower, child[k].upper);
            double prims = (double)(child[k].end - child[k].begin) * per_prim;
            if ((over_bottom && prims <= BOTTOM_SPHERES) || (plan && child[k].axis < 0))
                continue;
            if (prims > PTR_BVH_LEAF_MAX && area > pick_area) {
                pick = k;
                pick_area = area;
            }
        }
        if (pick < 0)
            break;
        if (plan) {
            plan->source[n] = pick;
            plan->test[n] = bvh_split_test(&child[pick]);
        }
        bvh_split(set, &child[pick], level >= MIDDLE_SPLIT_LEVEL, scratch, &child[pick],
                  &child[n]);
    }
    *count = n;
}

/* A node's children at this level as n samples of its prims split them,
 * each standing for per_prim prims (see grow_node), in plan, and the
 * samples each child took in sampled (unless NULL): the prims are then
 * sorted into them at once (bvh_split_children), where splitting them one
 * split at a time took a pass for each level of the node's splits, about
 * three, each moving every prim (docs/intersectors.md, "Nodes planned from
 * samples"). plan->count is 1 where the samples give no split (all at one
 * centre). */
static void plan_children(const BvhPrimSet *samples, size_t n, int level, double per_prim,
                          BvhPrim *scratch, BvhChildren *plan, size_t sampled[PTR_BVH_WIDTH])
{
    BvhCandidate range, child[PTR_BVH_WIDTH];
    bvh_candidate_init(samples, &range, 0, n, NULL, NULL);
    grow_node(samples, scratch, &range, level, per_prim, child, &plan->count, plan);
    for (int k = 0; sampled && k < plan->count; k++)
        sampled[k] = child[k].end - child[k].begin;
}

static PtrResult build_node(Build *build, Worker *w, NodeArray *nodes, TaskList *tasks,
                            const BvhCandidate *range, const BvhChildren *presorted,
                            NodeKind kind, int level, size_t *index, int *depth,
                            PtrError *err);

/* Makes the node of this kind at this level over the children child[0 .. n
 * - 1] in nodes (its index in *index), and its inner children below it that
 * are neither parts nor tasks, on the thread w (NULL for the root, which
 * has none); depth: levels below the node, not counting parts and tasks.
 * tasks: where a node of the top level puts its tasks. grandchildren:
 * NULL, or child k's prims sorted into its children, where
 * grandchildren[k].count is above 1 (plan_below). */
static PtrResult make_node(Build *build, Worker *w, NodeArray *nodes, TaskList *tasks,
                           const BvhCandidate child[PTR_BVH_WIDTH],
                           const BvhChildren *grandchildren, int n, NodeKind kind, int level,
                           size_t *index, int *depth, PtrError *err)
{
    PtrResult r;
    if ((r = node_array_add(nodes, index, err)) != PTR_OK)
        return r;
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
        const BvhCandidate *c = &child[k];
        node.lower_x[k] = c->lower[0];
        node.lower_y[k] = c->lower[1];
        node.lower_z[k] = c->lower[2];
        node.upper_x[k] = c->upper[0];
        node.upper_y[k] = c->upper[1];
        node.upper_z[k] = c->upper[2];
        size_t count = c->end - c->begin;
        if (count <= PTR_BVH_LEAF_MAX) {
            node.child[k] = (uint32_t)(build->first_sphere + c->begin);
            node.leaf_count[k] = (uint32_t)count;
            continue;
        }
        node.leaf_count[k] = 0;
        if (kind != NODE_TASK && count <= build->task_spheres) {
            uint32_t task;
            r = add_task(tasks, c, kind != NODE_ROOT, grandchildren ? &grandchildren[k] : NULL,
                         level + 1, &task, err);
            if (r != PTR_OK)
                return r;
            node.child[k] = TASK_FLAG | task;
            continue;
        }
        if (kind == NODE_ROOT) {
            node.child[k] = PART_FLAG | (uint32_t)build->part_count;
            build->parts[build->part_count++] = (Part){ .range = *c, .level = level + 1 };
            continue;
        }
        size_t inner;
        int below_depth;
        r = build_node(build, w, nodes, tasks, c, grandchildren ? &grandchildren[k] : NULL, kind,
                       level + 1, &inner, &below_depth, err);
        if (r != PTR_OK)
            return r;
        node.child[k] = (uint32_t)inner;
        if (below_depth + 1 > *depth)
            *depth = below_depth + 1;
    }
    nodes->nodes[self] = node; /* after the children: the array may have moved */
    return PTR_OK;
}

/* The candidates of children's ranges and boxes, child[0 .. count - 1]
 * (see bvh_candidate_init). */
static void candidates_of(const BvhPrimSet *set, const BvhChildren *children,
                          BvhCandidate child[PTR_BVH_WIDTH])
{
    for (int k = 0; k < children->count; k++)
        bvh_candidate_init(set, &child[k], children->begin[k], children->end[k],
                           children->lower[k], children->upper[k]);
}

/* m of the n prims, evenly spaced, in samples, which may be prims itself
 * (sample j is prim j n / m, never one before it). */
static void take_samples(const BvhPrim *prims, size_t n, size_t m, BvhPrim *samples)
{
    for (size_t j = 0; j < m; j++) {
        /* Each a cache miss the prefetchers do not foresee: fetched ahead,
         * they overlap. (j n is below 2^18 2^31: no overflow.) */
        if (j + PLAN_AHEAD < m)
            _mm_prefetch((const char *)&prims[(j + PLAN_AHEAD) * n / m], _MM_HINT_T0);
        samples[j] = prims[j * n / m];
    }
}

/* For each child k of plan over range at this level whose samples
 * (sampled[k], each standing for per_prim prims) put it over
 * BVH_PLANNED_ABOVE prims, its own children planned in grandchildren[k],
 * from samples of range's prims, one in PLAN_SHARE up to PTR_BVH_WIDTH
 * PLAN_SAMPLES, sorted into plan's children: up to PLAN_SAMPLES of those
 * a child took, evenly spaced. grandchildren[k].count is 1 for the others.
 * Returns whether any child has its children planned: the prims are then
 * sorted into plan's children and theirs in one pass, where a pass for
 * each level moved every prim twice as often (docs/intersectors.md, "Two
 * levels planned at once"). Every grandchild so planned holds a prim: it
 * holds a sample, which is one of the prims, tested the same way. A child
 * planned so may hold no more than BVH_PLANNED_ABOVE prims in the end:
 * then its plan stands, where it would have been split by the binned
 * split of all its prims. w->sort: reserved for range. */
static int plan_below(Build *build, Worker *w, const BvhCandidate *range, int level,
                      const BvhChildren *plan, const size_t sampled[PTR_BVH_WIDTH],
                      double per_prim, BvhChildren grandchildren[PTR_BVH_WIDTH])
{
    int planned[PTR_BVH_WIDTH], any = 0;
    for (int k = 0; k < plan->count; k++) {
        grandchildren[k].count = 1;
        planned[k] = level + 1 < MIDDLE_SPLIT_LEVEL &&
                     (double)sampled[k] * per_prim > BVH_PLANNED_ABOVE;
        any |= planned[k];
    }
    if (!any)
        return 0;
    const size_t n = range->end - range->begin, most = PTR_BVH_WIDTH * PLAN_SAMPLES;
    const size_t m = n / PLAN_SHARE < most ? n / PLAN_SHARE : most;
    take_samples(build->set.prims + range->begin, n, m, w->samples);
    const BvhPrimSet samples = set_over(build, w->samples);
    BvhChildren split = *plan;
    bvh_split_children(&samples, 0, m, &split, NULL, &w->sort);
    for (int k = 0; k < plan->count; k++) {
        const size_t took = split.end[k] - split.begin[k];
        if (!planned[k] || took == 0)
            continue;
        BvhPrim *own = w->samples + split.begin[k];
        const size_t used = took < PLAN_SAMPLES ? took : PLAN_SAMPLES;
        take_samples(own, took, used, own); /* in place: sample j is at j or after */
        const BvhPrimSet child_samples = set_over(build, own);
        const double child_per_prim = (double)n / (double)m * (double)took / (double)used;
        plan_children(&child_samples, used, level + 1, child_per_prim, w->scratch,
                      &grandchildren[k], NULL);
    }
    return 1;
}

/* The node's children as samples of its prims, one in PLAN_SHARE up to
 * PLAN_SAMPLES, evenly spaced, split them, each sample standing for as many
 * prims as there are to a sample, in plan, and the prims sorted into them,
 * in child[0 .. *count - 1], and into their children where they are
 * planned too (grandchildren, see plan_below). *count is 1 where the samples gave
 * no split (all at one centre): the prims as they were. Fails only for
 * memory.
 *
 * Planned from PLAN_SAMPLES whatever its size, a node of 195,000 prims
 * (512 of them at 10^8 spheres) spent a third of its time on its samples,
 * where one in 16 takes an eighth; the trees' surface area heuristic cost
 * moved by 0.04% at most (docs/intersectors.md, "Fewer samples for smaller
 * nodes"). */
static PtrResult plan_node(Build *build, Worker *w, const BvhCandidate *range, int level,
                           BvhCandidate child[PTR_BVH_WIDTH],
                           BvhChildren grandchildren[PTR_BVH_WIDTH], int *count, PtrError *err)
{
    const size_t n = range->end - range->begin;
    const size_t m = n / PLAN_SHARE < PLAN_SAMPLES ? n / PLAN_SHARE : PLAN_SAMPLES;
    const BvhPrimSet samples = set_over(build, w->samples);
    take_samples(build->set.prims + range->begin, n, m, w->samples);
    BvhChildren plan;
    size_t sampled[PTR_BVH_WIDTH];
    const double per_prim = (double)n / (double)m;
    plan_children(&samples, m, level, per_prim, w->scratch, &plan, sampled);
    *count = 1;
    child[0] = *range;
    if (plan.count == 1)
        return PTR_OK;
    if (bvh_sort_room_reserve(&w->sort, n) != PTR_OK)
        return bvh_out_of_memory(err);
    const int two_levels =
        plan_below(build, w, range, level, &plan, sampled, per_prim, grandchildren);
    /* Every child holds a prim: each holds a sample (the heuristic makes
     * no empty side), which is one of the prims, tested the same way. */
    bvh_split_children(&build->set, range->begin, range->end, &plan,
                       two_levels ? grandchildren : NULL, &w->sort);
    candidates_of(&build->set, &plan, child);
    *count = plan.count;
    return PTR_OK;
}

/* Builds the node of this kind at this level over range (its split found,
 * where it has one: see bvh_candidate_init) into nodes: see make_node.
 * presorted: NULL, or range's prims sorted into the node's children
 * where presorted->count is above 1 (plan_below). */
static PtrResult build_node(Build *build, Worker *w, NodeArray *nodes, TaskList *tasks,
                            const BvhCandidate *range, const BvhChildren *presorted,
                            NodeKind kind, int level, size_t *index, int *depth,
                            PtrError *err)
{
    BvhCandidate child[PTR_BVH_WIDTH];
    BvhChildren *grandchildren = NULL; /* planned with the children, where they are */
    int n = 1;
    PtrResult r = PTR_OK;
    if (presorted && presorted->count > 1) {
        n = presorted->count;
        candidates_of(&build->set, presorted, child);
    } else if (range->end - range->begin > BVH_PLANNED_ABOVE && level < MIDDLE_SPLIT_LEVEL) {
        /* On the heap: the recursion holds a node's for as long as its
         * children build. */
        if (!(grandchildren = malloc(PTR_BVH_WIDTH * sizeof *grandchildren)))
            return bvh_out_of_memory(err);
        r = plan_node(build, w, range, level, child, grandchildren, &n, err);
    }
    if (r == PTR_OK && n == 1) {
        free(grandchildren); /* no plan: no children planned */
        grandchildren = NULL;
        grow_node(&build->set, w->scratch, range, level, 1.0, child, &n, NULL);
    }
    if (r == PTR_OK)
        r = make_node(build, w, nodes, tasks, child, grandchildren, n, kind, level, index, depth,
                      err);
    free(grandchildren);
    return r;
}

static size_t part_size(const Part *p)
{
    return p->range.end - p->range.begin;
}

static size_t task_size(const Task *t)
{
    return t->range.end - t->range.begin;
}

/* Makes tasks ready to take, kept as a heap with the largest first; under
 * the pool's lock, or before its threads start. Fails only for memory. */
static int pool_add_ready(Pool *pool, TaskList *tasks)
{
    if (pool->ready_count + tasks->count > pool->ready_capacity) {
        size_t capacity = 2 * (pool->ready_count + tasks->count);
        Task **grown = realloc(pool->ready, capacity * sizeof *grown);
        if (!grown)
            return 0;
        pool->ready = grown;
        pool->ready_capacity = capacity;
    }
    for (size_t i = 0; i < tasks->count; i++) {
        size_t at = pool->ready_count++;
        for (; at > 0 && task_size(pool->ready[(at - 1) / 2]) < task_size(&tasks->tasks[i]);
             at = (at - 1) / 2)
            pool->ready[at] = pool->ready[(at - 1) / 2];
        pool->ready[at] = &tasks->tasks[i];
    }
    return 1;
}

/* The largest ready task, taken from the pool (NULL if none is ready);
 * under the pool's lock. */
static Task *pool_take_task(Pool *pool)
{
    if (pool->ready_count == 0)
        return NULL;
    Task *largest = pool->ready[0], *last = pool->ready[--pool->ready_count];
    size_t at = 0;
    for (;;) {
        size_t child = 2 * at + 1;
        if (child >= pool->ready_count)
            break;
        if (child + 1 < pool->ready_count &&
            task_size(pool->ready[child + 1]) > task_size(pool->ready[child]))
            child++;
        if (task_size(pool->ready[child]) <= task_size(last))
            break;
        pool->ready[at] = pool->ready[child];
        at = child;
    }
    pool->ready[at] = last;
    return largest;
}

/* Whether part p was built on the thread w (else it ran out of memory). */
static int build_part(Build *build, Worker *w, Part *p)
{
    if (!worker_ready(w))
        return 0;
    BvhCandidate range;
    size_t root;
    bvh_candidate_init(&build->set, &range, p->range.begin, p->range.end, p->range.lower,
                       p->range.upper);
    return build_node(build, w, &p->nodes, &p->tasks, &range, NULL, NODE_PART, p->level, &root,
                      &p->nodes.depth, NULL) == PTR_OK;
}

/* Whether task t was built on the thread w (else it ran out of memory). */
static int build_task(Build *build, Worker *w, Task *t)
{
    if (!worker_ready(w))
        return 0;
    BvhCandidate range = t->range;
    size_t root;
    /* Room for a node to PRIMS_A_NODE of its prims: a tree has about one
     * node to 50 prims (1.96 million over 10^8 random spheres), so a task's
     * array seldom grows, where growing from 64 nodes copied its nodes and
     * faulted in fresh pages for them at each doubling (at 10^8 a task's
     * 8 MB of nodes: 3.6% of the build's and import's time in the kernel's
     * page clearing under make_node); the end it does not use is never
     * faulted in. */
    const size_t room = task_size(t) / PRIMS_A_NODE;
    if (!node_array_grow(&t->nodes, room > 64 ? room : 64))
        return 0;
    if (!t->split_found)
        bvh_candidate_init(&build->set, &range, range.begin, range.end, range.lower,
                           range.upper);
    return build_node(build, w, &t->nodes, NULL, &range, &t->presorted, NODE_TASK, t->level,
                      &root, &t->nodes.depth, NULL) == PTR_OK;
}

/* Takes parts, then tasks, until none is left or will be, or the pool
 * has failed, building them on the thread w. */
static void pool_work(Pool *pool, Worker *w)
{
    Build *build = pool->build;
    pthread_mutex_lock(&pool->lock);
    for (;;) {
        if (!pool->failed && pool->next_part < build->part_count) {
            Part *p = &build->parts[pool->part_order[pool->next_part++]];
            pool->parts_running++;
            pthread_mutex_unlock(&pool->lock);
            const int built = build_part(build, w, p);
            pthread_mutex_lock(&pool->lock);
            pool->parts_running--;
            if (!built || !pool_add_ready(pool, &p->tasks))
                pool->failed = 1;
            pthread_cond_broadcast(&pool->wake);
            continue;
        }
        Task *t = pool->failed ? NULL : pool_take_task(pool);
        if (t) {
            pthread_mutex_unlock(&pool->lock);
            const int built = build_task(build, w, t);
            pthread_mutex_lock(&pool->lock);
            pool->failed |= !built;
            continue;
        }
        if (pool->parts_running == 0)
            break;
        pthread_cond_wait(&pool->wake, &pool->lock);
    }
    pthread_mutex_unlock(&pool->lock);
}

static void worker_free(Worker *w)
{
    free(w->scratch);
    free(w->samples);
    bvh_sort_room_free(&w->sort);
}

/* A thread of the pool but the build's own. */
static void *pool_thread(void *arg)
{
    Worker w = { 0 };
    pool_work(arg, &w);
    worker_free(&w);
    return NULL;
}

/* Builds the parts and every task, the root's and the parts', on all
 * threads from one pool (see Pool), w the build's own thread's. */
static PtrResult run_pool(Build *build, Worker *w, PtrError *err)
{
    Pool pool = { .build = build };
    for (size_t i = 0; i < build->part_count; i++) {
        size_t j = i;
        for (; j > 0 && part_size(&build->parts[pool.part_order[j - 1]]) <
                            part_size(&build->parts[i]);
             j--)
            pool.part_order[j] = pool.part_order[j - 1];
        pool.part_order[j] = i;
    }
    PtrThread **ids = malloc((size_t)build->threads * sizeof *ids);
    if (!ids || !pool_add_ready(&pool, &build->root_tasks)) {
        free(ids);
        free(pool.ready);
        return bvh_out_of_memory(err);
    }
    pthread_mutex_init(&pool.lock, NULL);
    pthread_cond_init(&pool.wake, NULL);
    int started = 0;
    while (started < build->threads - 1 && (ids[started] = ptr_thread_start(pool_thread, &pool)))
        started++;
    pool_work(&pool, w);
    for (int i = 0; i < started; i++)
        ptr_thread_join(ids[i]);
    free(ids);
    free(pool.ready);
    pthread_mutex_destroy(&pool.lock);
    pthread_cond_destroy(&pool.wake);
    return pool.failed ? bvh_out_of_memory(err) : PTR_OK;
}

/* Frees the tasks' node arrays and the list. */
static void free_tasks(TaskList *list)
{
    for (size_t i = 0; i < list->count; i++)
        free(list->tasks[i].nodes.nodes);
    free(list->tasks);
    *list = (TaskList){ 0 };
}

/* True for a lane of an inner node that holds a child node (or a part or a
 * task not yet laid out): not a leaf, not empty. */
static int inner_child(const PtrBvhNode *node, int k)
{
    return node->leaf_count[k] == 0 && node->lower_x[k] <= node->upper_x[k];
}

/* Copies the array from to joined[start ..], each inner child's index moved
 * by start and each task's number (a part's) by first_task. */
static void place_nodes(PtrBvhNode *joined, size_t start, NodeArray *from, size_t first_task)
{
    PtrBvhNode *nodes = joined + start;
    memcpy(nodes, from->nodes, from->count * sizeof *nodes);
    for (size_t j = 0; j < from->count; j++)
        for (int k = 0; k < PTR_BVH_WIDTH; k++)
            if (inner_child(&nodes[j], k))
                nodes[j].child[k] += (uint32_t)((nodes[j].child[k] & TASK_FLAG) ? first_task
                                                                                 : start);
}

/* Makes top the root and its parts' nodes in one array, and build->tasks
 * the root's and the parts' tasks, in the order a depth-first build on one
 * thread makes them: the root, then each part's nodes in the order of the
 * root's lanes; each task where the root or its part refers to it. Frees
 * the parts' node arrays, and their task lists and the root's, whose tasks
 * (built, their nodes with them) move to build->tasks. */
static PtrResult join_parts(Build *build, NodeArray *top, PtrError *err)
{
    size_t node_total = top->count, task_total = build->root_tasks.count;
    for (size_t i = 0; i < build->part_count; i++) {
        node_total += build->parts[i].nodes.count;
        task_total += build->parts[i].tasks.count;
    }
    PtrBvhNode *nodes = aligned_alloc(64, node_total * sizeof *nodes);
    Task *tasks = malloc((task_total ? task_total : 1) * sizeof *tasks);
    if (!nodes || !tasks) {
        free(nodes);
        free(tasks);
        return bvh_out_of_memory(err);
    }
    memcpy(nodes, top->nodes, top->count * sizeof *nodes);
    size_t node_count = top->count, task_count = 0;
    PtrBvhNode *root = &nodes[0];
    for (int k = 0; k < PTR_BVH_WIDTH; k++) {
        if (!inner_child(root, k))
            continue;
        if (root->child[k] & TASK_FLAG) {
            tasks[task_count] = build->root_tasks.tasks[root->child[k] & ~TASK_FLAG];
            root->child[k] = TASK_FLAG | (uint32_t)task_count++;
            continue;
        }
        Part *p = &build->parts[root->child[k] & ~PART_FLAG];
        memcpy(tasks + task_count, p->tasks.tasks, p->tasks.count * sizeof *tasks);
        place_nodes(nodes, node_count, &p->nodes, task_count);
        free(p->nodes.nodes);
        p->nodes.nodes = NULL;
        root->child[k] = (uint32_t)node_count;
        node_count += p->nodes.count;
        task_count += p->tasks.count;
        if (p->nodes.depth + 1 > top->depth)
            top->depth = p->nodes.depth + 1;
        free(p->tasks.tasks);
        p->tasks = (TaskList){ 0 };
    }
    free(build->root_tasks.tasks);
    build->root_tasks = (TaskList){ 0 };
    free(top->nodes);
    top->nodes = nodes;
    top->count = top->capacity = node_total;
    build->tasks = (TaskList){ tasks, task_count, task_total };
    return PTR_OK;
}

/* The tasks' arrays are laid out in batches of about this many bytes, each
 * on all threads, the heap trimmed after each: glibc keeps freed blocks of a
 * few megabytes for itself, and the tree must not be in memory twice. (Only
 * on the calling thread: glibc's malloc_trim on two threads at once is not
 * safe where another allocator serves malloc, as under AddressSanitizer.)
 * A batch's nodes go on the pages of the arrays the batch before copied
 * (the first batch's on those of the prims, which the write-back left in the
 * bank): faulted in afresh, the tree's 500 MB at 10^8 spheres took 122,000
 * faults. (Batches of 32 MB laid out 10^8 spheres' nodes in no less
 * time.) */
enum { TRIM_BYTES = 8 << 20 };

typedef struct LayOut {
    Build *build;
    PtrBvhNode *nodes;
    const size_t *start; /* where each task's nodes go */
} LayOut;

/* Copies tasks begin .. end - 1 to their places, each inner child index by
 * its task's start. */
static void lay_out_tasks(void *arg, size_t begin, size_t end)
{
    const LayOut *l = arg;
    for (size_t i = begin; i < end; i++)
        place_nodes(l->nodes, l->start[i], &l->build->tasks.tasks[i].nodes, 0);
}

/* One node array: the top level's first, then each task's, with every task
 * reference and every inner child index moved to its final place, on pages
 * from bank (see TRIM_BYTES). */
static PtrResult lay_out(Build *build, NodeArray *top, PtrBvh *bvh, PtrPageBank *bank,
                         PtrError *err)
{
    size_t *start = malloc((build->tasks.count + 1) * sizeof *start);
    if (!start)
        return bvh_out_of_memory(err);
    size_t total = top->count;
    for (size_t i = 0; i < build->tasks.count; i++) {
        start[i] = total;
        total += build->tasks.tasks[i].nodes.count;
    }
    PtrBvhNode *nodes = aligned_alloc(64, total * sizeof *nodes);
    if (!nodes) {
        free(start);
        return bvh_out_of_memory(err);
    }
    memcpy(nodes, top->nodes, top->count * sizeof *nodes);
    LayOut l = { build, nodes, start };
    Task *tasks = build->tasks.tasks;
    const size_t count = build->tasks.count;
    for (size_t first = 0; first < count;) {
        size_t last = first, bytes = 0;
        while (last < count && bytes < TRIM_BYTES)
            bytes += tasks[last++].nodes.count * sizeof *nodes;
        if (!ptr_pages_take(bank, nodes, start[first] * sizeof *nodes,
                            (start[last - 1] + tasks[last - 1].nodes.count) * sizeof *nodes)) {
            free(start);
            free(nodes);
            return bvh_out_of_memory(err);
        }
        /* The prims' pages (write_back) the first batch did not take go
         * back: the layout holds no more than its batch beyond the tree. */
        if (first == 0)
            ptr_pages_free(bank);
        ptr_parallel_ranges(build->threads, first, last, lay_out_tasks, &l);
        for (size_t i = first; i < last; i++) {
            ptr_pages_put(last < count ? bank : NULL, tasks[i].nodes.nodes, 0,
                          tasks[i].nodes.count * sizeof *nodes);
            free(tasks[i].nodes.nodes);
            tasks[i].nodes.nodes = NULL;
        }
        malloc_trim(0);
        first = last;
    }
    /* The depth of the top level counts a task as one level; add the rest. */
    int depth = 0;
    for (size_t j = 0; j < top->count; j++)
        for (int k = 0; k < PTR_BVH_WIDTH; k++)
            if (inner_child(&nodes[j], k) && (nodes[j].child[k] & TASK_FLAG)) {
                const Task *t = &build->tasks.tasks[nodes[j].child[k] & ~TASK_FLAG];
                nodes[j].child[k] = (uint32_t)start[t - build->tasks.tasks];
                if (t->nodes.depth > depth)
                    depth = t->nodes.depth;
            }
    free(start);
    bvh->nodes = nodes;
    bvh->node_count = total;
    bvh->depth = top->depth + 1 + depth;
    return PTR_OK;
}

typedef struct SphereWrite {
    PtrSpheres *spheres;
    const BvhPrim *prims;
    size_t first;            /* where prims[0] goes */
    const PtrSpheres *aside; /* see bvh_prim_store */
} SphereWrite;

static void write_spheres(void *arg, size_t begin, size_t end)
{
    const SphereWrite *w = arg;
    for (size_t i = begin; i < end; i++)
        bvh_prim_store(&w->prims[i], w->spheres, w->first + i, w->aside);
}

/* Writes the tree's spheres back to the scene's arrays from the prims, in
 * the tree's order: a sequential write where a gather would read 10^8
 * scattered entries (but for the material and attributes of a scene whose
 * prims hold places: see bvh_rest_aside). Each step's spheres go on the
 * pages of the prims the step before read (the first step's on those of the
 * spheres ptr_bvh_prims copied last), so that the two copies are never both
 * whole, and the arrays' pages are not faulted in afresh; bank keeps the
 * last prims' pages for the nodes. Frees the prims. Fails only for memory,
 * where the kernel lost pages it moved (ptr_pages_take). */
static PtrResult write_back(PtrSpheres *s, BvhPrim *prims, size_t prim_count, size_t first,
                            const PtrSpheres *aside, int threads, PtrPageBank *bank,
                            PtrError *err)
{
    SphereWrite w = { s, prims, first, aside };
    PtrResult r = PTR_OK;
    for (size_t begin = 0; begin < prim_count; begin += PTR_PAGE_STEP) {
        const size_t end = prim_count - begin > PTR_PAGE_STEP ? begin + PTR_PAGE_STEP
                                                              : prim_count;
        if (!ptr_spheres_take_pages(s, bank, first + begin, first + end)) {
            r = bvh_out_of_memory(err);
            break;
        }
        ptr_parallel_ranges(threads, begin, end, write_spheres, &w);
        if (end == prim_count) /* the layout gets one step's pages, as this did */
            ptr_pages_free(bank);
        ptr_pages_put(bank, prims, begin * sizeof *prims, end * sizeof *prims);
    }
    free(prims);
    return r;
}

/* The root's children (see the head): its splits planned from PLAN_SAMPLES
 * of the tree's spheres, evenly spaced, or all of them where they are no
 * more, binned by bin, on the thread w. Fails only for memory. */
static PtrResult plan_root(const PtrSpheres *spheres, int threads, const size_t *huge_index,
                           size_t huge_count, BvhBinFn bin, Worker *w, BvhChildren *plan,
                           PtrError *err)
{
    plan->count = 1;
    if (!worker_ready(w))
        return bvh_out_of_memory(err);
    BvhPrimSet samples = { .prims = w->samples, .bin = bin };
    const size_t n = ptr_bvh_samples(spheres, threads, huge_index, huge_count, samples.prims,
                                     PLAN_SAMPLES, &samples.magnitude);
    if (n > 0)
        plan_children(&samples, n, 0, (double)(spheres->count - huge_count) / (double)n,
                      w->scratch, plan, NULL);
    return PTR_OK;
}

PtrResult ptr_bvh_build(PtrBvh *bvh, PtrSpheres *spheres, size_t count, int threads,
                        PtrCpuLevel level, PtrError *err)
{
    memset(bvh, 0, sizeof *bvh);
    if (spheres->count >= TASK_FLAG)
        return bvh_out_of_memory(err);
    Build build = { .threads = ptr_thread_count(threads),
                    .set.bin = bvh_bin_for_level(level).bin };
    /* The prims and huge take the tree's spheres, whose pages the scene's
     * arrays give up meanwhile; the spheres after them stay. One bank of
     * pages goes from stage to stage: the spheres' pages under the prims and
     * then under the arrays written back, the prims' under those arrays and
     * then under the nodes. */
    PtrPageBank bank = { 0 };
    BvhPrim huge[PTR_HUGE_MAX];
    size_t huge_index[PTR_HUGE_MAX];
    BvhChildren root;
    Worker w = { 0 }; /* this thread's */
    /* Where the prims cannot hold a sphere's material and attributes, the
     * arrays of them stay whole. */
    PtrSpheres aside = { 0 };
    const PtrSpheres *gather = bvh_rest_by_place(spheres) ? &aside : NULL;
    PtrResult r = gather ? bvh_rest_aside(spheres, count, &aside, err) : PTR_OK;
    PtrSpheres tree_part = *spheres;
    tree_part.count = count;
    build.set.prims = malloc((count ? count : 1) * sizeof *build.set.prims);
    NodeArray top = { 0 };
    size_t prim_count = 0;
    if (r == PTR_OK && !build.set.prims)
        r = bvh_out_of_memory(err);
    if (r == PTR_OK)
        r = ptr_bvh_huge(&tree_part, build.threads, huge, huge_index, &bvh->huge_count, err);
    if (r == PTR_OK)
        r = plan_root(&tree_part, build.threads, huge_index, bvh->huge_count, build.set.bin, &w,
                      &root, err);
    if (r == PTR_OK)
        r = ptr_bvh_prims(&tree_part, build.threads, huge_index, bvh->huge_count, &root,
                          build.set.prims, &prim_count, &build.set.magnitude, &bank, err);
    build.first_sphere = bvh->huge_count;
    build.task_spheres = prim_count / TASKS_PER_TREE > TASK_SPHERES_MIN
                             ? prim_count / TASKS_PER_TREE : TASK_SPHERES_MIN;
    if (r == PTR_OK && prim_count > 0) {
        /* Their ranges and boxes: the parts and tasks find their splits on
         * their threads (build_part, build_task). */
        BvhCandidate child[PTR_BVH_WIDTH];
        int n = root.count;
        for (int k = 0; k < n; k++) {
            child[k] = (BvhCandidate){ .begin = root.begin[k], .end = root.end[k], .axis = -1 };
            memcpy(child[k].lower, root.lower[k], sizeof child[k].lower);
            memcpy(child[k].upper, root.upper[k], sizeof child[k].upper);
        }
        /* Samples that gave the root no split (all at one centre: the build
         * splits such a range in the middle of its order, which no test of
         * a prim can say) leave it to the prims: their best split where
         * they are few enough to bin, else the middle of their order (see
         * bvh_candidate_init), as for a planned node whose samples give
         * none. */
        if (n == 1) {
            BvhCandidate range;
            bvh_candidate_init(&build.set, &range, 0, prim_count, root.lower[0], root.upper[0]);
            grow_node(&build.set, w.scratch, &range, 0, 1.0, child, &n, NULL);
        }
        size_t index;
        r = make_node(&build, NULL, &top, &build.root_tasks, child, NULL, n, NODE_ROOT, 0,
                      &index, &top.depth, err);
        if (r == PTR_OK)
            r = run_pool(&build, &w, err);
        if (r == PTR_OK)
            r = join_parts(&build, &top, err);
    }
    if (r == PTR_OK) {
        r = write_back(spheres, build.set.prims, prim_count, bvh->huge_count, gather,
                       build.threads, &bank, err);
        build.set.prims = NULL;
    }
    if (r == PTR_OK) {
        SphereWrite first = { spheres, huge, 0, gather };
        write_spheres(&first, 0, bvh->huge_count);
        /* From here on a sphere's position decides a tie (see PtrSpheres),
         * and the file's order is the leaves' (see BvhPrim). */
        free(spheres->id);
        spheres->id = NULL;
    }
    bvh_rest_free(&aside);
    free(build.set.prims);
    /* Laying the tree out in one array needs memory of its own: it comes
     * once the prims are gone. */
    if (r == PTR_OK && prim_count > 0)
        r = lay_out(&build, &top, bvh, &bank, err);
    ptr_pages_free(&bank);
    worker_free(&w);
    free_tasks(&build.tasks);
    for (size_t i = 0; i < build.part_count; i++) {
        free(build.parts[i].nodes.nodes);
        free_tasks(&build.parts[i].tasks);
    }
    free_tasks(&build.root_tasks);
    free(top.nodes);
    if (r != PTR_OK)
        ptr_bvh_free(bvh);
    return r;
}

void ptr_bvh_free(PtrBvh *bvh)
{
    free(bvh->nodes);
    memset(bvh, 0, sizeof *bvh);
}
