/* Connected components by union-find over the triangles' vertex indices and
 * a hash of the vertices' positions (unwelded exports: every triangle its
 * own vertices), each fitted and checked; linear in the mesh's size. */
#include "mesh_spheres.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

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

static uint64_t position_hash(const double p[3])
{
    uint64_t h = 1469598103934665603u;
    for (int k = 0; k < 3; k++) {
        double x = p[k] + 0.0; /* -0 and +0 are one position */
        uint64_t bits;
        memcpy(&bits, &x, sizeof bits);
        h = (h ^ bits) * 1099511628211u;
        h ^= h >> 29;
    }
    return h;
}

/* Joins the vertices of equal positions, through an open-addressed table
 * of twice as many slots as vertices. */
static int unite_positions(const PtrMeshSource *mesh, uint32_t *parent)
{
    size_t size = 16;
    while (size < 2 * mesh->vertex_count)
        size *= 2;
    uint32_t *table = malloc(size * sizeof *table);
    if (!table)
        return 0;
    memset(table, 0xff, size * sizeof *table);
    for (size_t v = 0; v < mesh->vertex_count; v++) {
        double p[3], q[3];
        mesh->position(mesh->user, v, p);
        for (size_t slot = position_hash(p) & (size - 1);; slot = (slot + 1) & (size - 1)) {
            if (table[slot] == UNSET) {
                table[slot] = (uint32_t)v;
                break;
            }
            mesh->position(mesh->user, table[slot], q);
            if (p[0] == q[0] && p[1] == q[1] && p[2] == q[2]) {
                unite(parent, (uint32_t)v, table[slot]);
                break;
            }
        }
    }
    free(table);
    return 1;
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

/* Clears is_sphere of a component with a vertex off its sphere or a
 * triangle's centroid too deep inside it. */
static void check(const PtrMeshSource *mesh, const uint32_t *label, PtrMeshSphere *spheres)
{
    const double slack = 2 * mesh->quantum;
    for (size_t v = 0; v < mesh->vertex_count; v++) {
        if (label[v] == UNSET)
            continue;
        PtrMeshSphere *s = &spheres[label[v]];
        double p[3];
        mesh->position(mesh->user, v, p);
        if (!(fabs(distance(p, s->centre) - s->radius) <=
              PTR_SPHERE_VERTEX_TOLERANCE * s->radius + slack))
            s->is_sphere = 0;
    }
    for (size_t t = 0; t < mesh->triangle_count; t++) {
        uint32_t tri[3];
        double centroid[3] = { 0, 0, 0 }, p[3];
        mesh->triangle(mesh->user, t, tri);
        for (int i = 0; i < 3; i++) {
            mesh->position(mesh->user, tri[i], p);
            for (int k = 0; k < 3; k++)
                centroid[k] += p[k] / 3.0;
        }
        PtrMeshSphere *s = &spheres[label[tri[0]]];
        if (!(distance(centroid, s->centre) + slack >= PTR_SPHERE_CENTROID_DEPTH * s->radius))
            s->is_sphere = 0;
    }
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
    ok = ok && label;
    if (ok) {
        memset(label, 0xff, (n ? n : 1) * sizeof *label);
        for (size_t t = 0; t < mesh->triangle_count; t++) {
            uint32_t tri[3];
            mesh->triangle(mesh->user, t, tri);
            const uint32_t root = find(parent, tri[0]);
            if (label[root] == UNSET)
                label[root] = (uint32_t)components++;
        }
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
            spheres[c].first_triangle = SIZE_MAX;
        for (size_t t = 0; t < mesh->triangle_count; t++) {
            uint32_t tri[3];
            mesh->triangle(mesh->user, t, tri);
            PtrMeshSphere *s = &spheres[parent[tri[0]]];
            if (s->first_triangle == SIZE_MAX)
                s->first_triangle = t;
        }
        fit(mesh, parent, spheres, components, bounds, bounds + 3 * components);
        check(mesh, parent, spheres);
    }
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
