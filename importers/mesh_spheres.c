/* Connected components by union-find over the triangles' vertex indices and
 * a hash of the vertices' positions (unwelded exports: every triangle its
 * own vertices), each fitted and checked; linear in the mesh's size. The
 * mesh's callbacks are called from several threads at once. */
#include "mesh_spheres.h"

#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "base/cpu.h"
#include "base/threads.h"

enum { UNSET = UINT32_MAX };

/* The root of v's set, halving the path on the way. */
static uint32_t find(uint32_t *parent, uint32_t v)
{
    while (parent[v] != v) {
        parent[v] = parent[parent[v]];
        v = parent[v];
    }
    return v;
}

/* The lower root becomes the root, so the sets do not depend on the order
 * of the unions. */
static void unite(uint32_t *parent, uint32_t a, uint32_t b)
{
    a = find(parent, a);
    b = find(parent, b);
    if (a < b)
        parent[b] = a;
    else if (b < a)
        parent[a] = b;
}

/* A hash of a position's bits: each coordinate multiplied apart, then
 * MurmurHash3's finaliser, so that the low bits the table uses depend on
 * every bit (positions often differ only in their high bits). */
static uint64_t position_hash(const double p[3])
{
    static const uint64_t odd[3] = { 0x9e3779b97f4a7c15u, 0xc2b2ae3d27d4eb4fu,
                                     0x165667b19e3779f9u };
    uint64_t h = 0;
    for (int k = 0; k < 3; k++) {
        double x = p[k] + 0.0; /* -0 and +0 are one position */
        uint64_t bits;
        memcpy(&bits, &x, sizeof bits);
        h ^= bits * odd[k];
        h = (h << 31) | (h >> 33);
    }
    h ^= h >> 33;
    h *= 0xff51afd7ed558ccdu;
    h ^= h >> 33;
    h *= 0xc4ceb9fe1a85ec53u;
    return h ^ (h >> 33);
}

/* Vertices of equal positions are found partition by partition (the top
 * bits of their hash), each partition's table small enough for the cache,
 * the partitions on all cores for a mesh this large or larger. */
enum { PARTITION_BITS = 10, PARTITIONS = 1 << PARTITION_BITS, PARALLEL_VERTICES = 1 << 16 };

typedef struct PositionMatch {
    const PtrMeshSource *mesh;
    uint64_t *hash;   /* a vertex */
    uint32_t *order;  /* the vertices, partition after partition, each in order */
    size_t start[PARTITIONS + 1]; /* partition p: order[start[p] .. start[p + 1] - 1] */
    uint32_t *match;  /* an earlier vertex of the same position, or UNSET */
    atomic_int failed; /* a table could not be allocated */
} PositionMatch;

static void hash_positions(void *arg, size_t from, size_t to)
{
    PositionMatch *pm = arg;
    for (size_t v = from; v < to; v++) {
        double p[3];
        pm->mesh->position(pm->mesh->user, v, p);
        pm->hash[v] = position_hash(p);
    }
}

static int same_position(const PtrMeshSource *mesh, size_t v, size_t w)
{
    double p[3], q[3];
    mesh->position(mesh->user, v, p);
    mesh->position(mesh->user, w, q);
    return p[0] == q[0] && p[1] == q[1] && p[2] == q[2];
}

/* Partitions from .. to - 1, through an open-addressed table of twice as
 * many slots as the largest has vertices. */
static void match_partitions(void *arg, size_t from, size_t to)
{
    PositionMatch *pm = arg;
    size_t largest = 0;
    for (size_t p = from; p < to; p++)
        largest = pm->start[p + 1] - pm->start[p] > largest ? pm->start[p + 1] - pm->start[p]
                                                            : largest;
    size_t size = 16;
    while (size < 2 * largest)
        size *= 2;
    uint32_t *table = malloc(size * sizeof *table);
    if (!table) {
        atomic_store(&pm->failed, 1);
        return;
    }
    for (size_t p = from; p < to; p++) {
        memset(table, 0xff, size * sizeof *table);
        for (size_t i = pm->start[p]; i < pm->start[p + 1]; i++) {
            const uint32_t v = pm->order[i];
            for (size_t slot = pm->hash[v] & (size - 1);; slot = (slot + 1) & (size - 1)) {
                const uint32_t w = table[slot];
                if (w == UNSET) {
                    table[slot] = v;
                    break;
                }
                if (pm->hash[w] == pm->hash[v] && same_position(pm->mesh, v, w)) {
                    pm->match[v] = w;
                    break;
                }
            }
        }
    }
    free(table);
}

/* Joins the vertices of equal positions. */
static int unite_positions(const PtrMeshSource *mesh, uint32_t *parent)
{
    const size_t n = mesh->vertex_count;
    PositionMatch *pm = malloc(sizeof *pm);
    if (!pm)
        return 0;
    pm->mesh = mesh;
    pm->hash = malloc((n ? n : 1) * sizeof *pm->hash);
    pm->order = malloc((n ? n : 1) * sizeof *pm->order);
    pm->match = malloc((n ? n : 1) * sizeof *pm->match);
    atomic_init(&pm->failed, 0);
    int ok = pm->hash && pm->order && pm->match;
    if (ok) {
        const int threads = n >= PARALLEL_VERTICES ? ptr_online_cpus() : 1;
        ptr_parallel_ranges(threads, 0, n, hash_positions, pm);
        size_t fill[PARTITIONS] = { 0 };
        for (size_t v = 0; v < n; v++)
            fill[pm->hash[v] >> (64 - PARTITION_BITS)]++;
        pm->start[0] = 0;
        for (size_t p = 0; p < PARTITIONS; p++) {
            pm->start[p + 1] = pm->start[p] + fill[p];
            fill[p] = pm->start[p];
        }
        for (size_t v = 0; v < n; v++) {
            pm->order[fill[pm->hash[v] >> (64 - PARTITION_BITS)]++] = (uint32_t)v;
            pm->match[v] = UNSET;
        }
        ptr_parallel_ranges(threads, 0, PARTITIONS, match_partitions, pm);
        ok = !atomic_load(&pm->failed);
        for (size_t v = 0; ok && v < n; v++)
            if (pm->match[v] != UNSET)
                unite(parent, (uint32_t)v, pm->match[v]);
    }
    free(pm->hash);
    free(pm->order);
    free(pm->match);
    free(pm);
    return ok;
}

static double distance(const double a[3], const double b[3])
{
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                (a[2] - b[2]) * (a[2] - b[2]));
}

/* The bounds of each component (lo, hi: 3 a component), then the fit. */
static void fit(const PtrMeshSource *mesh, const uint32_t *label, PtrMeshSphere *spheres,
                size_t count, double *lo, double *hi)
{
    for (size_t c = 0; c < 3 * count; c++) {
        lo[c] = HUGE_VAL;
        hi[c] = -HUGE_VAL;
    }
    for (size_t v = 0; v < mesh->vertex_count; v++) {
        if (label[v] == UNSET)
            continue;
        double p[3];
        mesh->position(mesh->user, v, p);
        for (int k = 0; k < 3; k++) {
            lo[3 * label[v] + k] = fmin(lo[3 * label[v] + k], p[k]);
            hi[3 * label[v] + k] = fmax(hi[3 * label[v] + k], p[k]);
        }
    }
    for (size_t c = 0; c < count; c++) {
        double extent = 0.0, smallest = HUGE_VAL;
        for (int k = 0; k < 3; k++) {
            const double e = hi[3 * c + k] - lo[3 * c + k];
            spheres[c].centre[k] = 0.5 * (lo[3 * c + k] + hi[3 * c + k]);
            extent = fmax(extent, e);
            smallest = fmin(smallest, e);
        }
        spheres[c].radius = 0.5 * extent;
        spheres[c].is_sphere = extent > 0.0 && isfinite(extent) &&
                               smallest + 2 * mesh->quantum >= PTR_SPHERE_EXTENT_RATIO * extent;
    }
}

/* The check of a mesh's components, on all cores for a large mesh: a
 * thread that finds a component off its sphere marks it in `off`. */
typedef struct Check {
    const PtrMeshSource *mesh;
    const uint32_t *label; /* a vertex's component, UNSET if no triangle uses it */
    const PtrMeshSphere *spheres;
    atomic_uchar *off;
} Check;

/* Marks the components of vertices from .. to - 1 that lie off their sphere. */
static void check_vertices(void *arg, size_t from, size_t to)
{
    const Check *c = arg;
    const double slack = 2 * c->mesh->quantum;
    for (size_t v = from; v < to; v++) {
        if (c->label[v] == UNSET)
            continue;
        const PtrMeshSphere *s = &c->spheres[c->label[v]];
        double p[3];
        c->mesh->position(c->mesh->user, v, p);
        if (!(fabs(distance(p, s->centre) - s->radius) <=
              PTR_SPHERE_VERTEX_TOLERANCE * s->radius + slack))
            atomic_store_explicit(&c->off[c->label[v]], 1, memory_order_relaxed);
    }
}

/* Marks the components of triangles from .. to - 1 whose centroid lies too
 * deep inside their sphere (compared at three times the scale: the sum of
 * the corners against three times the centre). */
static void check_triangles(void *arg, size_t from, size_t to)
{
    const Check *c = arg;
    const double slack = 2 * c->mesh->quantum;
    for (size_t t = from; t < to; t++) {
        uint32_t tri[3];
        double sum[3] = { 0, 0, 0 }, p[3], centre[3];
        c->mesh->triangle(c->mesh->user, t, tri);
        for (int i = 0; i < 3; i++) {
            c->mesh->position(c->mesh->user, tri[i], p);
            for (int k = 0; k < 3; k++)
                sum[k] += p[k];
        }
        const PtrMeshSphere *s = &c->spheres[c->label[tri[0]]];
        for (int k = 0; k < 3; k++)
            centre[k] = 3 * s->centre[k];
        if (!(distance(sum, centre) + 3 * slack >= 3 * PTR_SPHERE_CENTROID_DEPTH * s->radius))
            atomic_store_explicit(&c->off[c->label[tri[0]]], 1, memory_order_relaxed);
    }
}

/* Clears is_sphere of a component with a vertex off its sphere or a
 * triangle's centroid too deep inside it. */
static int check(const PtrMeshSource *mesh, const uint32_t *label, PtrMeshSphere *spheres,
                 size_t count)
{
    Check c = { mesh, label, spheres, malloc((count ? count : 1) * sizeof *c.off) };
    if (!c.off)
        return 0;
    for (size_t k = 0; k < count; k++)
        atomic_init(&c.off[k], 0);
    const int threads = mesh->vertex_count >= PARALLEL_VERTICES ? ptr_online_cpus() : 1;
    ptr_parallel_ranges(threads, 0, mesh->vertex_count, check_vertices, &c);
    ptr_parallel_ranges(threads, 0, mesh->triangle_count, check_triangles, &c);
    for (size_t k = 0; k < count; k++)
        spheres[k].is_sphere = spheres[k].is_sphere && !atomic_load(&c.off[k]);
    free(c.off);
    return 1;
}

/* Numbers each root's component in the order of first triangles (label:
 * a root's number), with the first triangle of each into *first (malloc'd). */
static int number_components(const PtrMeshSource *mesh, uint32_t *parent, uint32_t *label,
                             size_t **first, size_t *count)
{
    size_t room = 16, n = 0;
    size_t *firsts = malloc(room * sizeof *firsts);
    for (size_t t = 0; firsts && t < mesh->triangle_count; t++) {
        uint32_t tri[3];
        mesh->triangle(mesh->user, t, tri);
        const uint32_t root = find(parent, tri[0]);
        if (label[root] != UNSET)
            continue;
        if (n == room) {
            size_t *more = realloc(firsts, 2 * room * sizeof *firsts);
            if (!more) {
                free(firsts);
                return 0;
            }
            firsts = more, room *= 2;
        }
        label[root] = (uint32_t)n;
        firsts[n++] = t;
    }
    *first = firsts;
    *count = n;
    return firsts != NULL;
}

PtrResult ptr_mesh_spheres(const PtrMeshSource *mesh, const char *path, PtrMeshSphere **out,
                           size_t *count, PtrError *err)
{
    const size_t n = mesh->vertex_count;
    uint32_t *parent = malloc((n ? n : 1) * sizeof *parent);
    PtrMeshSphere *spheres = NULL;
    double *bounds = NULL;
    size_t components = 0;
    int ok = parent != NULL;
    for (size_t v = 0; ok && v < n; v++)
        parent[v] = (uint32_t)v;
    ok = ok && unite_positions(mesh, parent);
    for (size_t t = 0; ok && t < mesh->triangle_count; t++) {
        uint32_t tri[3];
        mesh->triangle(mesh->user, t, tri);
        unite(parent, tri[0], tri[1]);
        unite(parent, tri[0], tri[2]);
    }
    /* Each root's component, numbered in the order of first triangles;
     * the labels go into parent once every vertex knows its root. */
    uint32_t *label = ok ? malloc((n ? n : 1) * sizeof *label) : NULL;
    size_t *first = NULL;
    ok = ok && label;
    if (ok) {
        memset(label, 0xff, (n ? n : 1) * sizeof *label);
        ok = number_components(mesh, parent, label, &first, &components);
    }
    if (ok) {
        spheres = malloc((components ? components : 1) * sizeof *spheres);
        bounds = malloc((components ? components : 1) * 6 * sizeof *bounds);
        ok = spheres && bounds;
    }
    if (ok) {
        for (size_t v = 0; v < n; v++) /* roots stay roots: each vertex its root */
            parent[v] = find(parent, (uint32_t)v);
        for (size_t v = 0; v < n; v++)
            parent[v] = label[parent[v]];
        for (size_t c = 0; c < components; c++)
            spheres[c].first_triangle = first[c];
        fit(mesh, parent, spheres, components, bounds, bounds + 3 * components);
        ok = check(mesh, parent, spheres, components);
    }
    free(first);
    free(parent);
    free(label);
    free(bounds);
    if (!ok) {
        free(spheres);
        return ptr_error_set(err, PTR_ERR_NOMEM, "%s: out of memory", path);
    }
    *out = spheres;
    *count = components;
    return PTR_OK;
}
