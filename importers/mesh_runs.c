/* Components found run by run. A joined mesh (gltf-transform join,
 * Blender's Join, bench/make_cloud --joined) holds one sphere's triangles
 * after another's, each over vertices of its own: its triangles fall into
 * runs, each over a range of vertices that no other run uses, so no
 * triangle joins two runs, and each run's components are found, fitted and
 * checked within it while its triangles and vertices are in the cache. That
 * is one pass over the mesh, where the union over the whole mesh
 * (mesh_spheres.c) takes several, over arrays as long as the mesh.
 *
 * The result is the union's to the bit where every component is a closed
 * surface by index (balance 4: mesh_spheres.c, find_closed_surfaces), for
 * the union then matches none of their vertices by position. Anything else
 * (a component open by index, as unwelded exports and seams split by
 * texture coordinates leave them; a triangle reaching back into an earlier
 * run; a run too large for the cache) leaves the mesh to the union, having
 * cost the pass so far.
 *
 * Where a run ends is decided from the triangles around that place alone
 * (scan_slice), so that threads given slices of the triangles agree on it:
 * each finds the runs that start in its slice, reading on past its end to
 * finish its last. */
#include "mesh_runs.h"

#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "base/threads.h"
#include "base/grow.h"
#include "mesh_component.h"

enum {
    UNSET = UINT32_MAX,
    /* How far before and after a place the triangles are looked at to start
     * a run there, and how many are read at once. */
    WINDOW = 1024,
    /* A run's vertices and triangles at most, so that its arrays stay
     * within a core's caches (a sphere of 40,962 vertices and 81,920
     * triangles, an icosphere divided six times, is one run). */
    RUN_VERTICES = 1 << 16,
    RUN_TRIANGLES = 1 << 17,
};

/* Triangles first .. end - 1, over vertices low .. high and no others;
 * once found, its components are spheres at .. at + count - 1 of its
 * slice's spheres, and its vertices' components, numbered in the run,
 * labels from labels_at on of its slice's labels (where they are asked
 * for). */
typedef struct Run {
    size_t first, end;
    uint32_t low, high;
    size_t at, count, labels_at;
} Run;

/* A component's bounds and checks while its run is found. */
typedef struct Fit {
    double lo[3], hi[3], centre3[3], sure[3];
    int off;
} Fit;

/* WINDOW triangles from t on (fewer at the mesh's end), each's least vertex
 * and greatest plus 1; past the mesh's end, none (its least UINT32_MAX). */
typedef struct Block {
    uint32_t tri[WINDOW][3], lo[WINDOW], hi1[WINDOW];
    size_t count;
} Block;

/* A slice's: the arrays of the run being found, grown to the largest run
 * (indexed by a vertex's place in its run) and freed when the slice is
 * through, and what the slice found. */
typedef struct Work {
    uint32_t (*tri)[3];
    size_t triangle_room;
    double (*pos)[3];
    uint32_t *parent;    /* a vertex's parent, then its root */
    uint32_t *component; /* a root's component, UNSET for a vertex no triangle uses */
    int32_t *balance;    /* a root's 2 V - F, V vertices and F triangles in its set */
    size_t vertex_room;
    Fit *fit;
    size_t fit_room;
    Block *blocks; /* 3 */
    Run *runs;
    size_t run_count, run_room;
    PtrMeshSphere *spheres;
    size_t sphere_count, sphere_room;
    uint32_t *labels;
    size_t label_count, label_room;
} Work;

typedef struct Runs {
    const PtrMeshSource *mesh;
    size_t slices;
    Work *work; /* one a slice */
    /* Every slice's runs in order, the slice each is found by, and the
     * run's first sphere in the result. */
    Run *all;
    size_t *slice_of, *base;
    size_t all_count, sphere_count;
    PtrMeshSphere *out;
    uint32_t *vertex_spheres; /* or NULL */
    atomic_int not_runs, no_memory;
} Runs;

static int going_on(Runs *r)
{
    return !atomic_load_explicit(&r->not_runs, memory_order_relaxed) &&
           !atomic_load_explicit(&r->no_memory, memory_order_relaxed);
}

static void give_up(Runs *r, int found)
{
    atomic_store_explicit(found < 0 ? &r->no_memory : &r->not_runs, 1, memory_order_relaxed);
}

/* w's arrays of a run's vertices and components, for nv vertices (a
 * closed surface has 3 vertices or more): 0 for memory. The positions set
 * the room; the other arrays of a vertex follow them. */
static int grow_vertices(Work *w, size_t nv)
{
    size_t room = w->vertex_room;
    if (ptr_grow((void **)&w->fit, &w->fit_room, nv / 3 + 1, sizeof *w->fit) != PTR_OK ||
        ptr_grow((void **)&w->pos, &room, nv, sizeof *w->pos) != PTR_OK)
        return 0;
    if (room == w->vertex_room)
        return 1;
    uint32_t *parent = realloc(w->parent, room * sizeof *parent);
    w->parent = parent ? parent : w->parent;
    uint32_t *component = realloc(w->component, room * sizeof *component);
    w->component = component ? component : w->component;
    int32_t *balance = realloc(w->balance, room * sizeof *balance);
    w->balance = balance ? balance : w->balance;
    if (!parent || !component || !balance)
        return 0;
    w->vertex_room = room;
    return 1;
}

/* Roots lie below the vertices of their sets (no thread shares these
 * arrays: plain stores). */
static uint32_t root_of(uint32_t *parent, uint32_t v)
{
    while (parent[v] != v)
        v = parent[v] = parent[parent[v]];
    return v;
}

/* Joins a's set and b's: 1 if they were two, 0 if they were one already. */
static uint32_t join(uint32_t *parent, uint32_t a, uint32_t b)
{
    if (parent[a] == parent[b]) /* most often, a sphere's triangles coming round a vertex */
        return 0;
    a = root_of(parent, a);
    b = root_of(parent, b);
    if (a == b)
        return 0;
    if (a < b)
        parent[b] = a;
    else
        parent[a] = b;
    return 1;
}

/* Each vertex's component (UNSET for one no triangle uses) into
 * w->parent, the components numbered in the order of their first
 * triangles, each checked to be closed: how many, or 0 where one is not
 * closed. A run's sets started as its nv vertices and joined made them
 * fewer. */
static size_t number_components(Work *w, const Run *run, uint32_t joined,
                                PtrMeshSphere *spheres)
{
    const uint32_t nv = run->high - run->low + 1;
    const size_t nt = run->end - run->first;
    uint32_t *parent = w->parent;
    /* Most often, one closed surface over every vertex. */
    if (joined + 1 == nv && 2 * (size_t)nv == nt + MESH_CLOSED_BALANCE) {
        for (uint32_t v = 0; v < nv; v++)
            parent[v] = 0;
        spheres[0].first_triangle = run->first;
        return 1;
    }
    for (uint32_t v = 0; v < nv; v++) {
        parent[v] = parent[parent[v]]; /* roots lie lower: parent[v]'s is flat already */
        w->component[v] = UNSET;
        w->balance[v] = 0;
    }
    for (uint32_t v = 0; v < nv; v++)
        w->balance[parent[v]] += 2;
    for (size_t t = 0; t < nt; t++)
        w->balance[parent[w->tri[t][0]]]--;
    size_t count = 0;
    for (size_t t = 0; t < nt; t++) {
        const uint32_t root = parent[w->tri[t][0]];
        if (w->component[root] != UNSET)
            continue;
        if (w->balance[root] != MESH_CLOSED_BALANCE)
            return 0;
        w->component[root] = (uint32_t)count;
        spheres[count++].first_triangle = run->first + t;
    }
    for (uint32_t v = 0; v < nv; v++)
        parent[v] = w->component[parent[v]];
    return count;
}

/* Run's components into w's spheres (and their labels into w's), found
 * with w's arrays, the run's triangles in w->tri: 1, or 0 where one is not
 * closed or the run has too many vertices, or -1 for memory. */
static int find_run(const Runs *r, Work *w, Run *run)
{
    const PtrMeshSource *mesh = r->mesh;
    if (run->high - run->low >= RUN_VERTICES)
        return 0;
    const uint32_t nv = run->high - run->low + 1;
    const size_t nt = run->end - run->first;
    if (!grow_vertices(w, nv) || ptr_grow((void **)&w->spheres, &w->sphere_room,
                                       w->sphere_count + nv / 3 + 1, sizeof *w->spheres) != PTR_OK)
        return -1;
    mesh->positions(mesh->user, run->low, nv, w->pos);
    uint32_t *label = w->parent, (*tri)[3] = w->tri, joined = 0;
    for (uint32_t v = 0; v < nv; v++)
        label[v] = v;
    for (size_t t = 0; t < nt; t++) {
        for (int k = 0; k < 3; k++)
            tri[t][k] -= run->low;
        joined += join(label, tri[t][0], tri[t][1]);
        joined += join(label, tri[t][0], tri[t][2]);
    }
    PtrMeshSphere *spheres = &w->spheres[w->sphere_count];
    const size_t count = number_components(w, run, joined, spheres);
    if (!count)
        return 0;
    Fit *fit = w->fit;
    const double(*pos)[3] = w->pos;
    for (size_t c = 0; c < count; c++)
        for (int k = 0; k < 3; k++)
            fit[c].lo[k] = HUGE_VAL, fit[c].hi[k] = -HUGE_VAL;
    for (uint32_t v = 0; v < nv; v++)
        if (label[v] != UNSET)
            mesh_bound_add(fit[label[v]].lo, fit[label[v]].hi, pos[v]);
    for (size_t c = 0; c < count; c++) {
        mesh_fit(fit[c].lo, fit[c].hi, mesh->quantum, &spheres[c], fit[c].sure);
        for (int k = 0; k < 3; k++)
            fit[c].centre3[k] = 3 * spheres[c].centre[k];
        fit[c].off = 0;
    }
    for (uint32_t v = 0; v < nv; v++) {
        const uint32_t c = label[v];
        if (c != UNSET && !fit[c].off)
            fit[c].off = mesh_vertex_off(&spheres[c], fit[c].sure, mesh->quantum, pos[v]);
    }
    for (size_t t = 0; t < nt; t++) {
        const uint32_t c = label[tri[t][0]];
        fit[c].off |= mesh_centroid_off(&spheres[c], fit[c].centre3, fit[c].sure, mesh->quantum,
                                        pos[tri[t][0]], pos[tri[t][1]], pos[tri[t][2]]);
    }
    for (size_t c = 0; c < count; c++)
        spheres[c].is_sphere = spheres[c].is_sphere && !fit[c].off;
    if (r->vertex_spheres) { /* kept until the slices' runs are known to fit together */
        if (ptr_grow((void **)&w->labels, &w->label_room, w->label_count + nv,
                     sizeof *w->labels) != PTR_OK)
            return -1;
        memcpy(&w->labels[w->label_count], label, nv * sizeof *label);
        run->labels_at = w->label_count;
        w->label_count += nv;
    }
    run->at = w->sphere_count;
    run->count = count;
    w->sphere_count += count;
    return 1;
}

/* The arrays of the run being found, once the slice is through. */
static void free_run_arrays(Work *w)
{
    free(w->tri);
    free(w->pos);
    free(w->parent);
    free(w->component);
    free(w->balance);
    free(w->fit);
    free(w->blocks);
}

/* Keeps a run that ended in slice s and finds it. Returns 0 where the mesh
 * is not in runs (a component is not closed; or the run reaches back into
 * the slice's last, which join_slices would find too, but only once every
 * slice is through) or memory ran out. */
static int end_run(Runs *r, size_t s, Run *run)
{
    Work *w = &r->work[s];
    const int reaches_back = w->run_count && run->low <= w->runs[w->run_count - 1].high;
    int found = reaches_back ? 0 : find_run(r, w, run);
    if (found > 0 && ptr_grow((void **)&w->runs, &w->run_room, w->run_count + 1,
                              sizeof *w->runs) != PTR_OK)
        found = -1;
    if (found <= 0) {
        give_up(r, found);
        return 0;
    }
    w->runs[w->run_count++] = *run;
    return 1;
}

/* Adds count triangles to slice s's open run, in its work's triangles:
 * 0 where the run grows too large for them. */
static int add_triangles(Runs *r, size_t s, Run *run, const uint32_t (*tri)[3], size_t count)
{
    const size_t held = run->end - run->first;
    Work *w = &r->work[s];
    if (!count)
        return 1;
    if (held + count > RUN_TRIANGLES) {
        give_up(r, 0);
        return 0;
    }
    if (ptr_grow((void **)&w->tri, &w->triangle_room, held + count, sizeof *w->tri) != PTR_OK) {
        give_up(r, -1);
        return 0;
    }
    memcpy(w->tri[held], tri, count * sizeof *tri);
    run->end += count;
    return 1;
}

/* The block of triangles from t on into b. */
static void read_block(const PtrMeshSource *mesh, size_t t, Block *b)
{
    b->count = t < mesh->triangle_count ? mesh->triangle_count - t : 0;
    b->count = b->count < WINDOW ? b->count : WINDOW;
    if (b->count)
        mesh->triangles(mesh->user, t, b->count, b->tri);
    for (size_t i = 0; i < b->count; i++) {
        const uint32_t *v = b->tri[i];
        const uint32_t ab_lo = v[0] < v[1] ? v[0] : v[1], ab_hi = v[0] < v[1] ? v[1] : v[0];
        b->lo[i] = v[2] < ab_lo ? v[2] : ab_lo;
        b->hi1[i] = (v[2] > ab_hi ? v[2] : ab_hi) + 1;
    }
    for (size_t i = b->count; i < WINDOW; i++)
        b->lo[i] = UINT32_MAX, b->hi1[i] = 0;
}

/* Where runs may start among block cur's triangles: a run can start at
 * triangle t where the WINDOW triangles before t use no vertex that the
 * WINDOW triangles from t on use, every vertex before below every vertex
 * after (the runs' ranges rise). That is decided from those
 * triangles alone, the same in every slice; a sphere of fewer triangles
 * (whatever their order) is never cut, and a later triangle that reaches
 * back into an ended run leaves the mesh to the union. */
static void find_starts(const Block *prev, const Block *cur, const Block *next,
                        unsigned char *start)
{
    uint32_t before[WINDOW + 1], after[WINDOW + 1]; /* of prev's i .. and of cur's i .. */
    before[WINDOW] = 0;
    after[WINDOW] = UINT32_MAX;
    for (size_t i = WINDOW; i-- > 0;) {
        before[i] = prev->hi1[i] > before[i + 1] ? prev->hi1[i] : before[i + 1];
        after[i] = cur->lo[i] < after[i + 1] ? cur->lo[i] : after[i + 1];
    }
    uint32_t cur_max = 0, next_min = UINT32_MAX; /* of cur's and next's 0 .. i - 1 */
    for (size_t i = 0; i < cur->count; i++) {
        const uint32_t max_before = before[i] > cur_max ? before[i] : cur_max;
        const uint32_t min_after = after[i] < next_min ? after[i] : next_min;
        start[i] = max_before <= min_after;
        cur_max = cur->hi1[i] > cur_max ? cur->hi1[i] : cur_max;
        next_min = next->lo[i] < next_min ? next->lo[i] : next_min;
    }
}

/* The runs that start in slice s's triangles, each found as it ends (the
 * last perhaps past the slice's end). */
static void scan_slice(Runs *r, size_t s)
{
    const size_t n = r->mesh->triangle_count;
    const size_t from = n * s / r->slices, to = n * (s + 1) / r->slices;
    if (from == to)
        return;
    Block *blocks = r->work[s].blocks = malloc(3 * sizeof *blocks);
    if (!blocks) {
        give_up(r, -1);
        return;
    }
    unsigned char start[WINDOW];
    Block *prev = &blocks[0], *cur = &blocks[1], *next = &blocks[2];
    read_block(r->mesh, from >= WINDOW ? from - WINDOW : 0, prev);
    if (from < WINDOW) { /* the triangles before the first, at prev's end */
        memmove(prev->hi1 + WINDOW - from, prev->hi1, from * sizeof *prev->hi1);
        memset(prev->hi1, 0, (WINDOW - from) * sizeof *prev->hi1);
    }
    read_block(r->mesh, from, cur);
    Run run;
    int open = 0;
    for (size_t t = from; t < n && going_on(r); t += WINDOW) {
        read_block(r->mesh, t + WINDOW, next);
        find_starts(prev, cur, next, start);
        size_t begin = 0; /* the block's first triangle of the open run */
        for (size_t i = 0; i < cur->count; i++) {
            if (!open && t + i >= to) /* the slice's runs all ended */
                return;
            if (!start[i]) {
                if (open) {
                    run.low = cur->lo[i] < run.low ? cur->lo[i] : run.low;
                    run.high = cur->hi1[i] - 1 > run.high ? cur->hi1[i] - 1 : run.high;
                }
                continue;
            }
            if (open && (!add_triangles(r, s, &run, &cur->tri[begin], i - begin) ||
                         !end_run(r, s, &run) || t + i >= to))
                return; /* the run starting at t + i is the next slice's */
            run = (Run){ .first = t + i, .end = t + i, .low = cur->lo[i],
                         .high = cur->hi1[i] - 1 };
            open = 1;
            begin = i;
        }
        if (open && !add_triangles(r, s, &run, &cur->tri[begin], cur->count - begin))
            return;
        Block *held = prev;
        prev = cur, cur = next, next = held;
    }
    if (open && going_on(r))
        end_run(r, s, &run);
}

static void scan_slices(void *arg, size_t from, size_t to)
{
    Runs *r = arg;
    for (size_t s = from; s < to; s++) {
        scan_slice(r, s);
        free_run_arrays(&r->work[s]);
    }
}

/* Every slice's runs in order into r->all: 0 where a run reaches back into
 * the one before, found by another slice. */
static int join_slices(Runs *r)
{
    size_t total = 0;
    for (size_t s = 0; s < r->slices; s++)
        total += r->work[s].run_count;
    r->all = malloc((total ? total : 1) * sizeof *r->all);
    r->slice_of = malloc((total ? total : 1) * sizeof *r->slice_of);
    r->base = malloc((total ? total : 1) * sizeof *r->base);
    if (!r->all || !r->slice_of || !r->base)
        return -1;
    size_t k = 0;
    for (size_t s = 0; s < r->slices; s++)
        for (size_t i = 0; i < r->work[s].run_count; i++, k++) {
            r->all[k] = r->work[s].runs[i];
            if (k && r->all[k - 1].high >= r->all[k].low)
                return 0;
            r->slice_of[k] = s;
            r->base[k] = r->sphere_count;
            r->sphere_count += r->all[k].count;
        }
    r->all_count = k;
    return 1;
}

/* Runs from .. to - 1: their spheres into the result, and their vertices'
 * spheres numbered in it, the vertices past each run up to the next one's
 * (and before the first) no triangle's. */
static void place_runs(void *arg, size_t from, size_t to)
{
    const Runs *r = arg;
    for (size_t i = from; i < to; i++) {
        const Run *run = &r->all[i];
        memcpy(&r->out[r->base[i]], &r->work[r->slice_of[i]].spheres[run->at],
               run->count * sizeof *r->out);
        uint32_t *labels = r->vertex_spheres;
        if (!labels)
            continue;
        const size_t base = r->base[i];
        const uint32_t *in_run = &r->work[r->slice_of[i]].labels[run->labels_at];
        for (size_t v = i ? run->low : 0; v < run->low; v++)
            labels[v] = UNSET;
        for (size_t v = run->low; v <= run->high; v++) {
            const uint32_t c = in_run[v - run->low];
            labels[v] = c == UNSET ? UNSET : (uint32_t)(base + c);
        }
        const size_t next = i + 1 < r->all_count ? r->all[i + 1].low : r->mesh->vertex_count;
        for (size_t v = (size_t)run->high + 1; v < next; v++)
            labels[v] = UNSET;
    }
}


/* The runs' spheres in order into r->out: 1, or -1 for memory. */
static int place(Runs *r, int threads)
{
    r->out = malloc((r->sphere_count ? r->sphere_count : 1) * sizeof *r->out);
    if (!r->out)
        return -1;
    ptr_parallel_ranges(threads, 0, r->all_count, place_runs, r);
    return 1;
}

PtrResult ptr_mesh_spheres_by_runs(const PtrMeshSource *mesh, int threads, const char *path,
                                   PtrMeshSphere **out, size_t *count,
                                   uint32_t **vertex_spheres, int *found, PtrError *err)
{
    *found = 0;
    if (!mesh->triangle_count || !mesh_may_close(mesh))
        return PTR_OK;
    /* A slice of 8 windows at least: each reads a window before it and
     * after it besides its own. */
    const size_t most = mesh->triangle_count / (8 * WINDOW);
    Runs r = { .mesh = mesh };
    r.slices = threads < 1 ? 1 : (size_t)threads < most ? (size_t)threads : most ? most : 1;
    r.work = calloc(r.slices, sizeof *r.work);
    int outcome = r.work ? 1 : -1;
    if (outcome > 0 && vertex_spheres) {
        r.vertex_spheres = malloc(mesh->vertex_count * sizeof *r.vertex_spheres);
        outcome = r.vertex_spheres ? 1 : -1;
    }
    if (outcome > 0) {
        ptr_parallel_ranges(threads, 0, r.slices, scan_slices, &r);
        outcome = atomic_load(&r.no_memory) ? -1 : atomic_load(&r.not_runs) ? 0 : 1;
    }
    if (outcome > 0)
        outcome = join_slices(&r);
    if (outcome > 0)
        outcome = place(&r, threads);
    for (size_t s = 0; r.work && s < r.slices; s++) {
        free(r.work[s].runs);
        free(r.work[s].spheres);
        free(r.work[s].labels);
    }
    free(r.work);
    free(r.all);
    free(r.slice_of);
    free(r.base);
    if (outcome <= 0) {
        free(r.out);
        free(r.vertex_spheres);
        return outcome < 0 ? ptr_error_set(err, PTR_ERR_NOMEM, "%s: out of memory", path)
                           : PTR_OK;
    }
    *out = r.out;
    *count = r.sphere_count;
    if (vertex_spheres)
        *vertex_spheres = r.vertex_spheres;
    *found = 1;
    return PTR_OK;
}
