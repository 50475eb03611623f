/* Connected components by union-find over the triangles' vertex indices and
 * the vertices' positions (unwelded exports: every triangle its own
 * vertices; only the vertices of parts open by index are matched by
 * position), each fitted and checked. Every pass is linear in the mesh's
 * size, reads it a block at a time through the mesh's callbacks, and runs on
 * all cores for a large mesh; what it finds does not depend on how the
 * passes are cut among threads. */
#include "mesh_spheres.h"

#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "base/cpu.h"
#include "base/threads.h"
#include "mesh_component.h"
#include "mesh_runs.h"

enum {
    UNSET = UINT32_MAX,
    BLOCK = 256,                 /* vertices or triangles read at once */
    PARALLEL_SIZE = 1 << 16,     /* vertices and triangles: a mesh this large on all cores */
    PARTITION_VERTICES = 4096,   /* about the vertices of one table of positions */
    /* At most 512 partitions: a slice's write buffers (a cache line a
     * partition) then stay in L1 and its pages in the TLB; more made
     * filing slower than the smaller tables made matching faster. */
    MAX_PARTITION_BITS = 9,
};

/* A vertex's parent in the union-find forest. Threads unite at once without
 * locks: a root links only to a lower root, by compare-and-swap, so parents
 * only ever point lower, and a find halves paths by swapping in an ancestor
 * for the parent it read (swapping, so that it never undoes a root stored
 * by flatten since). Each set's root is then its lowest vertex, as serial
 * unions leave it. */
typedef _Atomic uint32_t Link;

static uint32_t link_of(Link *parent, uint32_t v)
{
    return atomic_load_explicit(&parent[v], memory_order_relaxed);
}

static uint32_t find(Link *parent, uint32_t v)
{
    for (uint32_t up; (up = link_of(parent, v)) != v;) {
        const uint32_t above = link_of(parent, up);
        if (above != up)
            atomic_compare_exchange_strong_explicit(&parent[v], &up, above, memory_order_relaxed,
                                                    memory_order_relaxed);
        v = above;
    }
    return v;
}

/* Joins a's set and b's: 1 if they were two, 0 if they were one already. */
static int unite(Link *parent, uint32_t a, uint32_t b)
{
    if (link_of(parent, a) == link_of(parent, b)) /* most often, once paths are short */
        return 0;
    for (;;) {
        a = find(parent, a);
        b = find(parent, b);
        if (a == b)
            return 0;
        uint32_t high = a > b ? a : b;
        const uint32_t low = a > b ? b : a;
        if (atomic_compare_exchange_weak_explicit(&parent[high], &high, low,
                                                  memory_order_relaxed, memory_order_relaxed))
            return 1;
    }
}

static int threads_for(const PtrMeshSource *mesh)
{
    return mesh->vertex_count + mesh->triangle_count >= PARALLEL_SIZE ? ptr_usable_cpus() : 1;
}

/* A hash of a position's bits: each coordinate multiplied apart, then
 * MurmurHash3's finaliser, so that the low bits the tables use and the high
 * bits the partitions use depend on every bit (positions often differ only
 * in their high bits). */
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

/* What the triangles make of a vertex: a triangle's first corner (so its
 * set has triangles), or, found before the positions are matched, on a
 * closed surface (so it is left out of the matching); else neither. */
enum { NEITHER, FIRST_CORNER, ON_CLOSED_SURFACE };

/* A vertex and the low bits of its position's hash. */
typedef struct Keyed {
    uint32_t key, vertex;
} Keyed;

/* Vertices of equal positions are found partition by partition (the top
 * bits of their hash), each partition's table small enough for the cache.
 * The vertices are cut into slices, one a thread up to MAX_SLICES; a slice
 * hashes each of its vertices once and files it under its partition, in
 * buckets it takes from a pool of its own and chains, so that no pass has
 * to count the partitions first: a partition's vertices are its chains, one
 * a slice.
 * Each chain ends in a part-empty bucket, and every chain that holds a
 * vertex touches its pages: hence the cap on slices, whatever the cores,
 * and a bucket the least power of two from MIN_BUCKET that holds a chain's
 * even share, up to MAX_BUCKET (4 KiB). For n vertices, S slices and P
 * partitions the pools hold n + S (P + 1) bucket keyed vertices, where
 * S P bucket is below 2n or at its floor S P MIN_BUCKET: at most
 * 5n + 2^21 (40 bytes a vertex and 16 MB), where a slice a core and 4 KiB
 * buckets came to 0.5 GB for 2M vertices on 256 cores. */
enum { MAX_SLICES = 32, MIN_BUCKET = 64, MAX_BUCKET = 512 };

typedef struct PositionMatch {
    const PtrMeshSource *mesh;
    Link *parent;
    const atomic_uchar *state; /* a vertex's, as above */
    Keyed *keyed;    /* the buckets, one after another */
    uint32_t *chain; /* a bucket's next in its chain */
    uint32_t *head;  /* slice s, partition p at [s * partitions + p]: its
                      * chain's first bucket */
    size_t *filed;   /* the same: how many vertices its chain holds */
    size_t slices, partitions;
    int bits;        /* partitions = 2^bits */
    int threads;
    size_t bucket;   /* keyed vertices a bucket */
    atomic_int failed; /* a buffer or table could not be allocated */
} PositionMatch;

static size_t slice_start(const PositionMatch *pm, size_t s)
{
    return pm->mesh->vertex_count * s / pm->slices;
}

/* A slice's pool, from this bucket to the next slice's: room for all its
 * vertices, every partition's last bucket part empty. */
static size_t pool_start(const PositionMatch *pm, size_t s)
{
    return slice_start(pm, s) / pm->bucket + s * (pm->partitions + 1);
}

static size_t partition_of(const PositionMatch *pm, uint64_t hash)
{
    return pm->bits ? (size_t)(hash >> (64 - pm->bits)) : 0;
}

/* Whether vertex v is matched by position. */
static int matched(const PositionMatch *pm, size_t v)
{
    return atomic_load_explicit(&pm->state[v], memory_order_relaxed) != ON_CLOSED_SURFACE;
}

/* The vertices among v .. end - 1 (at most a block of them) that can equal
 * another, with their hashes: how many; a block of closed surfaces' is not
 * read. A position with a NaN equals nothing, so it is left out: kept, all
 * NaNs of one bit pattern would share a hash and every one would probe past
 * all the earlier ones. */
static size_t hash_block(const PositionMatch *pm, size_t v, size_t end, uint64_t *hash,
                         uint32_t *vertex)
{
    double p[BLOCK][3];
    const size_t count = end - v < BLOCK ? end - v : BLOCK;
    size_t open = 0;
    for (size_t i = 0; i < count; i++)
        open += matched(pm, v + i);
    if (!open)
        return 0;
    pm->mesh->positions(pm->mesh->user, v, count, p);
    size_t kept = 0;
    for (size_t i = 0; i < count; i++)
        if (matched(pm, v + i) && !isnan(p[i][0]) && !isnan(p[i][1]) && !isnan(p[i][2])) {
            hash[kept] = position_hash(p[i]);
            vertex[kept++] = (uint32_t)(v + i);
        }
    return kept;
}

/* The keyed vertices a partition's buffer holds until they are written out
 * together (a cache line): written one by one, each vertex to its own
 * partition's bucket, they would miss the cache and the TLB each time. */
enum { LINE = 8 };

/* Files count keyed vertices at once into slice s's chain of partition p,
 * starting a bucket where the last is full (a line never straddles two:
 * LINE divides a bucket, and only a chain's last line is short). */
static void file_line(PositionMatch *pm, size_t s, size_t p, uint32_t *tail, size_t *pool,
                      const Keyed *line, size_t count)
{
    const size_t at = s * pm->partitions + p;
    if (pm->filed[at] % pm->bucket == 0) {
        const uint32_t bucket = (uint32_t)(*pool)++;
        if (pm->filed[at])
            pm->chain[tail[p]] = bucket;
        else
            pm->head[at] = bucket;
        tail[p] = bucket;
    }
    memcpy(&pm->keyed[(size_t)tail[p] * pm->bucket + pm->filed[at] % pm->bucket], line,
           count * sizeof *line);
    pm->filed[at] += count;
}

static void file_slices(void *arg, size_t from, size_t to)
{
    PositionMatch *pm = arg;
    Keyed (*line)[LINE] = malloc(pm->partitions * sizeof *line);
    unsigned char *held = calloc(pm->partitions, 1);
    uint32_t *tail = malloc(pm->partitions * sizeof *tail);
    uint64_t hash[BLOCK];
    uint32_t vertex[BLOCK];
    for (size_t s = from; line && held && tail && s < to; s++) {
        size_t pool = pool_start(pm, s);
        for (size_t v = slice_start(pm, s), end = slice_start(pm, s + 1); v < end; v += BLOCK)
            for (size_t i = 0, n = hash_block(pm, v, end, hash, vertex); i < n; i++) {
                const size_t p = partition_of(pm, hash[i]);
                line[p][held[p]++] = (Keyed){ (uint32_t)hash[i], vertex[i] };
                if (held[p] == LINE) {
                    file_line(pm, s, p, tail, &pool, line[p], LINE);
                    held[p] = 0;
                }
            }
        for (size_t p = 0; p < pm->partitions; p++) {
            if (held[p])
                file_line(pm, s, p, tail, &pool, line[p], held[p]);
            held[p] = 0;
        }
    }
    if (!line || !held || !tail)
        atomic_store(&pm->failed, 1);
    free(line);
    free(held);
    free(tail);
}

static int same_position(const PtrMeshSource *mesh, uint32_t v, uint32_t w)
{
    const uint32_t both[2] = { v, w };
    double p[2][3];
    mesh->gather(mesh->user, both, 2, p);
    return p[0][0] == p[1][0] && p[0][1] == p[1][1] && p[0][2] == p[1][2];
}

static size_t partition_count(const PositionMatch *pm, size_t p)
{
    size_t count = 0;
    for (size_t s = 0; s < pm->slices; s++)
        count += pm->filed[s * pm->partitions + p];
    return count;
}

/* Partition p's keyed vertices, its chains one after another, into k. */
static void gather_partition(const PositionMatch *pm, size_t p, Keyed *k)
{
    for (size_t s = 0; s < pm->slices; s++) {
        size_t left = pm->filed[s * pm->partitions + p];
        for (uint32_t b = pm->head[s * pm->partitions + p]; left; b = pm->chain[b]) {
            const size_t count = left < pm->bucket ? left : pm->bucket;
            memcpy(k, &pm->keyed[(size_t)b * pm->bucket], count * sizeof *k);
            k += count;
            left -= count;
        }
    }
}

/* Partitions from .. to - 1, each through an open-addressed table of twice
 * as many slots as it has vertices: a vertex is united with the first of
 * its position (which is first does not change the sets). */
static void match_partitions(void *arg, size_t from, size_t to)
{
    PositionMatch *pm = arg;
    size_t largest = 0;
    for (size_t p = from; p < to; p++)
        largest = partition_count(pm, p) > largest ? partition_count(pm, p) : largest;
    size_t size = 16;
    while (size < 2 * largest)
        size *= 2;
    uint32_t *table = malloc(size * sizeof *table);
    Keyed *k = malloc((largest ? largest : 1) * sizeof *k);
    for (size_t p = from; table && k && p < to; p++) {
        const size_t count = partition_count(pm, p);
        gather_partition(pm, p, k);
        size_t mask = 15;
        while (mask + 1 < 2 * count)
            mask = 2 * mask + 1;
        memset(table, 0xff, (mask + 1) * sizeof *table);
        for (uint32_t i = 0; i < count; i++)
            for (size_t slot = k[i].key & mask;; slot = (slot + 1) & mask) {
                const uint32_t j = table[slot];
                if (j == UNSET) {
                    table[slot] = i;
                    break;
                }
                if (k[j].key == k[i].key && same_position(pm->mesh, k[i].vertex, k[j].vertex)) {
                    unite(pm->parent, k[i].vertex, k[j].vertex);
                    break;
                }
            }
    }
    if (!table || !k)
        atomic_store(&pm->failed, 1);
    free(table);
    free(k);
}

/* The slices and partitions of a mesh's vertices, on threads: decided once,
 * so that the scratch keyed_room sizes and the pools unite_positions files
 * into are cut alike (the CPUs the process may run on can change between
 * two questions). */
static void plan_partitions(PositionMatch *pm, const PtrMeshSource *mesh, int threads)
{
    *pm = (PositionMatch){ .mesh = mesh, .threads = threads, .bucket = MIN_BUCKET,
                           .slices = threads < MAX_SLICES ? (size_t)threads : MAX_SLICES };
    while (pm->bits < MAX_PARTITION_BITS &&
           ((size_t)PARTITION_VERTICES << pm->bits) < mesh->vertex_count)
        pm->bits++;
    pm->partitions = (size_t)1 << pm->bits;
    while (pm->bucket < MAX_BUCKET && pm->bucket * pm->slices * pm->partitions < mesh->vertex_count)
        pm->bucket *= 2;
}

/* The keyed vertices unite_positions needs for its buckets: at least one a
 * vertex. */
static size_t keyed_room(const PositionMatch *pm)
{
    return pool_start(pm, pm->slices) * pm->bucket;
}

/* Joins the vertices of equal positions, but for those on closed surfaces,
 * as planned, keyed (keyed_room of them) as scratch. */
static int unite_positions(PositionMatch *pm, Link *parent, const atomic_uchar *state,
                           Keyed *keyed)
{
    pm->parent = parent;
    pm->state = state;
    pm->keyed = keyed;
    const size_t buckets = pool_start(pm, pm->slices);
    pm->chain = malloc(buckets * sizeof *pm->chain);
    pm->head = malloc(pm->slices * pm->partitions * sizeof *pm->head);
    pm->filed = calloc(pm->slices * pm->partitions, sizeof *pm->filed);
    atomic_init(&pm->failed, 0);
    int ok = pm->chain && pm->head && pm->filed;
    if (ok) {
        ptr_parallel_ranges((int)pm->slices, 0, pm->slices, file_slices, pm);
        if (!atomic_load(&pm->failed))
            ptr_parallel_ranges(pm->threads, 0, pm->partitions, match_partitions, pm);
        ok = !atomic_load(&pm->failed);
    }
    free(pm->chain);
    free(pm->head);
    free(pm->filed);
    return ok;
}

/* What the passes share. */
typedef struct Passes {
    const PtrMeshSource *mesh;
    Link *parent; /* a vertex's parent; from flatten on, its root; from
                   * bound_vertices on, its component, UNSET if no triangle
                   * uses it */
    atomic_uchar *state; /* a vertex's: NEITHER, FIRST_CORNER, or from
                          * find_closed_surfaces on, ON_CLOSED_SURFACE */
    Link *balance; /* until the positions are matched, in label's place:
                    * at the root of a set by index, 2 V - F of its V
                    * vertices and F triangles (modulo 2^32) */
    Link *label;  /* UNSET, or USED for a triangle's first corner or a
                   * vertex on a closed surface and, from flatten on, for
                   * the root of its set; from number_roots on, a root's
                   * component */
    PtrMeshSphere *spheres;
    atomic_size_t *first;   /* a component's first triangle */
    _Atomic double *bounds; /* 6 a component: the least x, y, z, the greatest */
    atomic_uchar *off;      /* whether a component lies off its sphere */
    double (*sure)[3];      /* a component's squared distances that pass its
                             * checks for certain (see mesh_sure_bands) */
    uint32_t *order;        /* a component's place among the sorted spheres */
    uint32_t *vertex_spheres; /* the caller's: each vertex's sphere, or NULL */
    int threads;
    atomic_size_t rejoined; /* the triangles' unions that found their two
                             * vertices in one set already */
} Passes;

enum { USED = UNSET - 1 };

static void start_sets(void *arg, size_t from, size_t to)
{
    const Passes *ps = arg;
    for (size_t v = from; v < to; v++) {
        atomic_init(&ps->parent[v], (uint32_t)v);
        atomic_init(&ps->state[v], NEITHER);
        atomic_init(&ps->balance[v], 0);
    }
}

static void label_used(void *arg, size_t from, size_t to)
{
    const Passes *ps = arg;
    for (size_t v = from; v < to; v++)
    {
        const int used = atomic_load_explicit(&ps->state[v], memory_order_relaxed) != NEITHER;
        atomic_init(&ps->label[v], used ? USED : UNSET);
    }
}

/* Joins each triangle's corners, counting the unions that join nothing (for
 * find_closed_surfaces). */
static void unite_triangles(void *arg, size_t from, size_t to)
{
    Passes *ps = arg;
    uint32_t tri[BLOCK][3];
    size_t rejoined = 0;
    for (size_t t = from; t < to; t += BLOCK) {
        const size_t count = to - t < BLOCK ? to - t : BLOCK;
        ps->mesh->triangles(ps->mesh->user, t, count, tri);
        for (size_t i = 0; i < count; i++) {
            rejoined += !unite(ps->parent, tri[i][0], tri[i][1]);
            rejoined += !unite(ps->parent, tri[i][0], tri[i][2]);
            atomic_store_explicit(&ps->state[tri[i][0]], FIRST_CORNER, memory_order_relaxed);
        }
    }
    atomic_fetch_add_explicit(&ps->rejoined, rejoined, memory_order_relaxed);
}

/* v's root where it is at most two links up, as it mostly is once the
 * vertices below v are flattened, without find's compare-and-swaps (the
 * root is stored in v next anyway); else find's. */
static uint32_t near_root(Link *parent, uint32_t v)
{
    const uint32_t above = link_of(parent, link_of(parent, v));
    return link_of(parent, above) == above ? above : find(parent, v);
}

/* Each vertex its root, and a root USED if a vertex of its set is. */
static void flatten(void *arg, size_t from, size_t to)
{
    const Passes *ps = arg;
    for (size_t v = from; v < to; v++) {
        const uint32_t root = near_root(ps->parent, (uint32_t)v);
        atomic_store_explicit(&ps->parent[v], root, memory_order_relaxed);
        if (root != v && link_of(ps->label, (uint32_t)v) == USED)
            atomic_store_explicit(&ps->label[root], USED, memory_order_relaxed);
    }
}

/* Additions to the balance of a stretch of one set's vertices or triangles
 * (a mesh's sets mostly lie in stretches), added at the stretch's end. */
typedef struct Tally {
    uint32_t root; /* UNSET before the first */
    uint32_t sum;
} Tally;

static void end_tally(const Passes *ps, const Tally *run)
{
    if (run->root != UNSET)
        atomic_fetch_add_explicit(&ps->balance[run->root], run->sum, memory_order_relaxed);
}

static void tally(const Passes *ps, Tally *run, uint32_t root, uint32_t amount)
{
    if (root != run->root) {
        end_tally(ps, run);
        *run = (Tally){ root, 0 };
    }
    run->sum += amount;
}

/* Each vertex its root by index, and 2 to its root's balance (a set by
 * index is a vertex no triangle uses, of balance 2, or triangles' corners
 * only). */
static void count_vertices(void *arg, size_t from, size_t to)
{
    const Passes *ps = arg;
    Tally run = { .root = UNSET };
    for (size_t v = from; v < to; v++) {
        const uint32_t root = near_root(ps->parent, (uint32_t)v);
        atomic_store_explicit(&ps->parent[v], root, memory_order_relaxed);
        tally(ps, &run, root, 2);
    }
    end_tally(ps, &run);
}

/* Takes 1 a triangle from its root's balance. */
static void count_triangles(void *arg, size_t from, size_t to)
{
    const Passes *ps = arg;
    Tally run = { .root = UNSET };
    uint32_t tri[BLOCK][3];
    for (size_t t = from; t < to; t += BLOCK) {
        const size_t count = to - t < BLOCK ? to - t : BLOCK;
        ps->mesh->triangles(ps->mesh->user, t, count, tri);
        for (size_t i = 0; i < count; i++)
            tally(ps, &run, link_of(ps->parent, tri[i][0]), UINT32_MAX); /* -1 */
    }
    end_tally(ps, &run);
}

/* A surface where every edge is shared by two triangles and that is a
 * sphere's (genus 0) has, by Euler's formula V - E + F = 2 with E = 3 F / 2,
 * V = F / 2 + 2: balance 4. A border (a hole, a seam split, a piece cut off
 * a sphere) leaves V larger, so a set of balance 4 is taken as closed: no
 * other part can belong to its sphere, and its vertices are not matched by
 * position. (The count does not look at edges: a set that is not a simple
 * surface, a torus with a flap, can have balance 4 too; it is then fitted
 * alone.) */
static void mark_closed(void *arg, size_t from, size_t to)
{
    const Passes *ps = arg;
    for (size_t v = from; v < to; v++)
        if (link_of(ps->balance, link_of(ps->parent, (uint32_t)v)) == MESH_CLOSED_BALANCE)
            atomic_store_explicit(&ps->state[v], ON_CLOSED_SURFACE, memory_order_relaxed);
}

/* The vertices of the sets by index that are closed surfaces, on closed
 * surfaces; for a mesh of 2^31 vertices or triangles, whose balances could
 * wrap around to 4, none. A set of F triangles whose 2 F unions found their
 * vertices joined already R times has 2 F - R + 1 vertices (every other
 * union added one), so balance 3 F - 2 R + 2: 4 needs 2 R = 3 F - 2, at
 * least R = 2 (F = 2: two triangles over the same three vertices). Where
 * the unions of the whole mesh found that fewer than twice (an unwelded
 * mesh: never), no set is closed, and the passes are not run. */
static void find_closed_surfaces(Passes *ps)
{
    const PtrMeshSource *mesh = ps->mesh;
    if (!mesh_may_close(mesh) || atomic_load(&ps->rejoined) < 2)
        return;
    ptr_parallel_ranges(ps->threads, 0, mesh->vertex_count, count_vertices, ps);
    ptr_parallel_ranges(ps->threads, 0, mesh->triangle_count, count_triangles, ps);
    ptr_parallel_ranges(ps->threads, 0, mesh->vertex_count, mark_closed, ps);
}

/* The roots of sets that have triangles, numbered in order (each set's root
 * is its lowest vertex): how many. */
static size_t number_roots(const Passes *ps)
{
    size_t n = 0;
    for (size_t v = 0; v < ps->mesh->vertex_count; v++)
        if (link_of(ps->parent, (uint32_t)v) == v && link_of(ps->label, (uint32_t)v) == USED)
            atomic_store_explicit(&ps->label[v], (uint32_t)n++, memory_order_relaxed);
    return n;
}

/* Components from .. to - 1 before their first vertex is bounded. */
static void start_components(void *arg, size_t from, size_t to)
{
    const Passes *ps = arg;
    for (size_t c = from; c < to; c++) {
        atomic_init(&ps->first[c], SIZE_MAX);
        for (int k = 0; k < 3; k++) {
            atomic_init(&ps->bounds[6 * c + k], HUGE_VAL);
            atomic_init(&ps->bounds[6 * c + 3 + k], -HUGE_VAL);
        }
        atomic_init(&ps->off[c], 0);
    }
}

static void lower_to(_Atomic double *bound, double x)
{
    double seen = atomic_load_explicit(bound, memory_order_relaxed);
    while (x < seen && !atomic_compare_exchange_weak_explicit(bound, &seen, x, memory_order_relaxed,
                                                              memory_order_relaxed))
        ;
}

static void raise_to(_Atomic double *bound, double x)
{
    double seen = atomic_load_explicit(bound, memory_order_relaxed);
    while (x > seen && !atomic_compare_exchange_weak_explicit(bound, &seen, x, memory_order_relaxed,
                                                              memory_order_relaxed))
        ;
}

/* Adds a run of one component's vertices' bounds to the component's. */
static void merge_bounds(const Passes *ps, uint32_t c, const double lo[3], const double hi[3])
{
    for (int k = 0; k < 3; k++) {
        lower_to(&ps->bounds[6 * c + k], lo[k]);
        raise_to(&ps->bounds[6 * c + 3 + k], hi[k]);
    }
}

/* Vertices v .. to - 1, at most a block of them: their positions into p and
 * their components, from their roots' labels, into c and their parents
 * (the relabelling, done in the pass that reads the positions). Returns
 * how many. */
static size_t relabel_block(const Passes *ps, size_t v, size_t to, double (*p)[3], uint32_t *c)
{
    const size_t count = to - v < BLOCK ? to - v : BLOCK;
    ps->mesh->positions(ps->mesh->user, v, count, p);
    for (size_t i = 0; i < count; i++) {
        c[i] = link_of(ps->label, link_of(ps->parent, (uint32_t)(v + i)));
        atomic_store_explicit(&ps->parent[v + i], c[i], memory_order_relaxed);
    }
    return count;
}

/* The bounds of a stretch of vertices of one component (a mesh's
 * components mostly lie in stretches), merged into the component's at the
 * stretch's end. */
typedef struct Stretch {
    uint32_t component; /* UNSET before the first */
    double lo[3], hi[3];
} Stretch;

static void bound_vertex(const Passes *ps, Stretch *run, uint32_t c, const double p[3])
{
    if (c != run->component) {
        if (run->component != UNSET)
            merge_bounds(ps, run->component, run->lo, run->hi);
        run->component = c;
        for (int k = 0; k < 3; k++)
            run->lo[k] = HUGE_VAL, run->hi[k] = -HUGE_VAL;
    }
    mesh_bound_add(run->lo, run->hi, p);
}

/* Relabels vertices from .. to - 1 with their components and adds them to
 * their components' bounds. */
static void bound_vertices(void *arg, size_t from, size_t to)
{
    const Passes *ps = arg;
    Stretch run = { .component = UNSET };
    double p[BLOCK][3];
    uint32_t c[BLOCK];
    for (size_t v = from; v < to; v += BLOCK)
        for (size_t i = 0, n = relabel_block(ps, v, to, p, c); i < n; i++)
            if (c[i] != UNSET)
                bound_vertex(ps, &run, c[i], p[i]);
    if (run.component != UNSET)
        merge_bounds(ps, run.component, run.lo, run.hi);
}

/* The fit of components from .. to - 1 to their bounds. */
static void fit(void *arg, size_t from, size_t to)
{
    const Passes *ps = arg;
    for (size_t c = from; c < to; c++) {
        double lo[3], hi[3];
        for (int k = 0; k < 3; k++) {
            lo[k] = atomic_load_explicit(&ps->bounds[6 * c + k], memory_order_relaxed);
            hi[k] = atomic_load_explicit(&ps->bounds[6 * c + 3 + k], memory_order_relaxed);
        }
        mesh_fit(lo, hi, ps->mesh->quantum, &ps->spheres[c], ps->sure[c]);
    }
}

static void mark_off(const Passes *ps, uint32_t c)
{
    atomic_store_explicit(&ps->off[c], 1, memory_order_relaxed);
}

/* Marks vertex p's component c (if any) if p lies off its sphere. */
static void check_vertex(const Passes *ps, uint32_t c, const double p[3])
{
    if (c != UNSET && mesh_vertex_off(&ps->spheres[c], ps->sure[c], ps->mesh->quantum, p))
        mark_off(ps, c);
}

/* The corners of a block's triangles: where their vertices lie within
 * 3 * BLOCK of each other (a mesh's triangles mostly use nearby vertices),
 * those vertices read at once, each once; else each corner read. Returns
 * the first vertex read at once, or UNSET where each corner was, and how
 * many positions were read in *read. */
static uint32_t read_corners(const PtrMeshSource *mesh, uint32_t (*tri)[3], size_t count,
                             double (*corner)[3], size_t *read)
{
    uint32_t lo = UNSET, hi = 0;
    for (size_t i = 0; i < count; i++)
        for (int k = 0; k < 3; k++) {
            lo = tri[i][k] < lo ? tri[i][k] : lo;
            hi = tri[i][k] > hi ? tri[i][k] : hi;
        }
    if (hi - lo < 3 * BLOCK) {
        *read = hi - lo + 1;
        mesh->positions(mesh->user, lo, *read, corner);
        return lo;
    }
    *read = 3 * count;
    mesh->gather(mesh->user, &tri[0][0], *read, corner);
    return UNSET;
}

/* Marks the components of triangles from .. to - 1 whose centroid lies too
 * deep inside their sphere (compared at three times the scale: the sum of
 * the corners against three times the centre), and finds each component's
 * first triangle. The positions read for the corners are checked as
 * vertices too: every vertex a triangle uses is a corner, so every one is
 * checked (some more than once, to the same effect), while the positions
 * are in the cache. */
static void check_triangles(void *arg, size_t from, size_t to)
{
    const Passes *ps = arg;
    uint32_t tri[BLOCK][3], last = UNSET;
    double corner[3 * BLOCK][3], centre3[3] = { 0, 0, 0 }; /* last's centre, times 3 */
    for (size_t t = from; t < to; t += BLOCK) {
        const size_t count = to - t < BLOCK ? to - t : BLOCK;
        ps->mesh->triangles(ps->mesh->user, t, count, tri);
        size_t read;
        const uint32_t first = read_corners(ps->mesh, tri, count, corner, &read);
        for (size_t i = 0; i < read; i++) {
            const uint32_t v = first == UNSET ? tri[i / 3][i % 3] : first + (uint32_t)i;
            check_vertex(ps, link_of(ps->parent, v), corner[i]);
        }
        for (size_t i = 0; i < count; i++) {
            const uint32_t c = link_of(ps->parent, tri[i][0]);
            if (c != last) { /* this thread's first triangle of c: the least of the threads' */
                last = c;
                size_t seen = atomic_load_explicit(&ps->first[c], memory_order_relaxed);
                while (t + i < seen && !atomic_compare_exchange_weak_explicit(
                                           &ps->first[c], &seen, t + i, memory_order_relaxed,
                                           memory_order_relaxed))
                    ;
                for (int k = 0; k < 3; k++)
                    centre3[k] = 3 * ps->spheres[c].centre[k];
            }
            const double *p[3];
            for (int j = 0; j < 3; j++)
                p[j] = corner[first == UNSET ? 3 * i + j : tri[i][j] - first];
            if (mesh_centroid_off(&ps->spheres[c], centre3, ps->sure[c], ps->mesh->quantum, p[0],
                                  p[1], p[2]))
                mark_off(ps, c);
        }
    }
}

/* Each vertex's place among the sorted spheres, from its component. */
static void label_vertices(void *arg, size_t from, size_t to)
{
    const Passes *ps = arg;
    for (size_t v = from; v < to; v++) {
        const uint32_t c = link_of(ps->parent, (uint32_t)v);
        ps->vertex_spheres[v] = c == UNSET ? UNSET : ps->order[c];
    }
}

/* ps->vertex_spheres filled, once the spheres are sorted: a sphere's first
 * triangle's corner gives the component it was numbered as. */
static int sort_labels(Passes *ps, size_t components)
{
    ps->order = malloc((components ? components : 1) * sizeof *ps->order);
    if (!ps->order)
        return 0;
    for (size_t i = 0; i < components; i++) {
        uint32_t tri[1][3];
        ps->mesh->triangles(ps->mesh->user, ps->spheres[i].first_triangle, 1, tri);
        ps->order[link_of(ps->parent, tri[0][0])] = (uint32_t)i;
    }
    ptr_parallel_ranges(ps->threads, 0, ps->mesh->vertex_count, label_vertices, ps);
    return 1;
}

static int by_first_triangle(const void *a, const void *b)
{
    const size_t x = ((const PtrMeshSphere *)a)->first_triangle;
    const size_t y = ((const PtrMeshSphere *)b)->first_triangle;
    return (x > y) - (x < y);
}

/* The components, numbered by their roots, fitted and checked into
 * ps->spheres (malloc'd, count of them), then put in the order of their
 * first triangles. */
static int fit_components(Passes *ps, size_t *count)
{
    const PtrMeshSource *mesh = ps->mesh;
    const int threads = ps->threads;
    const size_t n = mesh->vertex_count;
    ptr_parallel_ranges(threads, 0, n, flatten, ps);
    const size_t components = number_roots(ps), room = components ? components : 1;
    ps->spheres = malloc(room * sizeof *ps->spheres);
    ps->first = malloc(room * sizeof *ps->first);
    ps->bounds = malloc(6 * room * sizeof *ps->bounds);
    ps->off = malloc(room * sizeof *ps->off);
    ps->sure = malloc(room * sizeof *ps->sure);
    if (!ps->spheres || !ps->first || !ps->bounds || !ps->off || !ps->sure)
        return 0;
    ptr_parallel_ranges(threads, 0, components, start_components, ps);
    ptr_parallel_ranges(threads, 0, n, bound_vertices, ps);
    ptr_parallel_ranges(threads, 0, components, fit, ps);
    ptr_parallel_ranges(threads, 0, mesh->triangle_count, check_triangles, ps);
    int sorted = 1;
    for (size_t c = 0; c < components; c++) {
        PtrMeshSphere *s = &ps->spheres[c];
        s->is_sphere = s->is_sphere && !atomic_load(&ps->off[c]);
        s->first_triangle = atomic_load(&ps->first[c]);
        sorted = sorted && (c == 0 || s[-1].first_triangle < s->first_triangle);
    }
    if (!sorted)
        qsort(ps->spheres, components, sizeof *ps->spheres, by_first_triangle);
    *count = components;
    return !ps->vertex_spheres || sort_labels(ps, components);
}

static PtrResult by_union(const PtrMeshSource *mesh, int threads, const char *path,
                          PtrMeshSphere **out, size_t *count, uint32_t **vertex_spheres,
                          PtrError *err)
{
    const size_t n = mesh->vertex_count ? mesh->vertex_count : 1;
    PositionMatch pm;
    plan_partitions(&pm, mesh, threads);
    /* The balances, the positions' keys, then the labels: one allocation,
     * its pages mapped once (keyed_room is at least a key, 8 bytes, a
     * vertex: room for a balance or a label, 4). */
    Keyed *scratch = malloc(keyed_room(&pm) * sizeof *scratch);
    Passes ps = { .mesh = mesh, .parent = malloc(n * sizeof *ps.parent),
                  .state = malloc(n * sizeof *ps.state),
                  .balance = (Link *)scratch, .label = (Link *)scratch,
                  .vertex_spheres = vertex_spheres ? malloc(n * sizeof *ps.vertex_spheres) : NULL,
                  .threads = threads };
    size_t components = 0;
    int ok = ps.parent && ps.state && scratch && (!vertex_spheres || ps.vertex_spheres);
    if (ok) {
        ptr_parallel_ranges(threads, 0, mesh->vertex_count, start_sets, &ps);
        ptr_parallel_ranges(threads, 0, mesh->triangle_count, unite_triangles, &ps);
        find_closed_surfaces(&ps);
    }
    ok = ok && unite_positions(&pm, ps.parent, ps.state, scratch);
    if (ok)
        ptr_parallel_ranges(threads, 0, mesh->vertex_count, label_used, &ps);
    ok = ok && fit_components(&ps, &components);
    free(ps.parent);
    free(ps.state);
    free(scratch);
    free(ps.first);
    free(ps.bounds);
    free(ps.off);
    free(ps.sure);
    free(ps.order);
    if (!ok) {
        free(ps.spheres);
        free(ps.vertex_spheres);
        return ptr_error_set(err, PTR_ERR_NOMEM, "%s: out of memory", path);
    }
    if (vertex_spheres)
        *vertex_spheres = ps.vertex_spheres;
    *out = ps.spheres;
    *count = components;
    return PTR_OK;
}

PtrResult ptr_mesh_spheres_by_union(const PtrMeshSource *mesh, const char *path,
                                    PtrMeshSphere **out, size_t *count,
                                    uint32_t **vertex_spheres, PtrError *err)
{
    return by_union(mesh, threads_for(mesh), path, out, count, vertex_spheres, err);
}

PtrResult ptr_mesh_spheres(const PtrMeshSource *mesh, const char *path, PtrMeshSphere **out,
                           size_t *count, uint32_t **vertex_spheres, PtrError *err)
{
    const int threads = threads_for(mesh);
    int found = 0;
    const PtrResult res =
        ptr_mesh_spheres_by_runs(mesh, threads, path, out, count, vertex_spheres, &found, err);
    if (res != PTR_OK || found)
        return res;
    return by_union(mesh, threads, path, out, count, vertex_spheres, err);
}
