/* A mesh as its reader sees it, a component's sphere fitted to its
 * vertices' bounds, and the checks that its vertices and triangles lie on
 * it (docs/scenes.md, "What becomes a sphere"): one definition for both
 * ways a mesh's components are found (mesh_spheres.c, mesh_runs.c), so that
 * both find the same spheres to the bit. */
#ifndef PTR_MESH_COMPONENT_H
#define PTR_MESH_COMPONENT_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>

/* A mesh as its reader sees it, read a block at a time (from several
 * threads at once): positions of vertices by range or by list, triangles'
 * three vertices by range (each below vertex_count: the reader has checked
 * them). */
typedef struct PtrMeshSource {
    size_t vertex_count, triangle_count;
    /* Vertices first .. first + count - 1. */
    void (*positions)(const void *user, size_t first, size_t count, double (*out)[3]);
    /* The count vertices listed. */
    void (*gather)(const void *user, const uint32_t *vertices, size_t count, double (*out)[3]);
    /* Triangles first .. first + count - 1. */
    void (*triangles)(const void *user, size_t first, size_t count, uint32_t (*out)[3]);
    const void *user;
    /* The step of the positions' storage (1 for integers, 1/255 for
     * normalised bytes, ...; 0 for floats): the check allows two of it. */
    double quantum;
} PtrMeshSource;

/* A component: the centre of its bounds and half their largest extent, the
 * first triangle in it, and whether its vertices lie on that sphere. */
typedef struct PtrMeshSphere {
    double centre[3], radius;
    size_t first_triangle;
    int is_sphere;
} PtrMeshSphere;

/* The relative tolerances of the check (docs/scenes.md says why): every
 * vertex within PTR_SPHERE_VERTEX_TOLERANCE of the radius from the sphere,
 * every triangle's centroid at least PTR_SPHERE_CENTROID_DEPTH of the radius
 * from the centre, the bounds' smallest extent at least
 * PTR_SPHERE_EXTENT_RATIO of their largest. */
#define PTR_SPHERE_VERTEX_TOLERANCE 0.1
#define PTR_SPHERE_CENTROID_DEPTH 0.88
#define PTR_SPHERE_EXTENT_RATIO 0.75

/* A set of V vertices and F triangles joined by index is a closed surface
 * where 2 V - F is this (mesh_spheres.c, find_closed_surfaces, says why);
 * its vertices are then not matched by position. */
enum { MESH_CLOSED_BALANCE = 4 };

/* Whether the sets of a mesh can be told closed: their balances are kept
 * in 32 bits, so a mesh of 2^31 vertices or triangles or more has none. */
static inline int mesh_may_close(const PtrMeshSource *mesh)
{
    return mesh->vertex_count < (size_t)1 << 31 && mesh->triangle_count < (size_t)1 << 31;
}

/* Bounds lo .. hi grown by position p; a coordinate that is not a number
 * is left out. */
static inline void mesh_bound_add(double lo[3], double hi[3], const double p[3])
{
    for (int k = 0; k < 3; k++) {
        lo[k] = p[k] < lo[k] ? p[k] : lo[k];
        hi[k] = p[k] > hi[k] ? p[k] : hi[k];
    }
}

/* The checks below compare distances, a square root each; most distances
 * are far from the checks' limits, and their squares show it without the
 * root. sure[0] .. sure[1]: a vertex's squared distance from the centre
 * that passes the vertex check for certain; sure[2] and above: three times
 * a centroid's from three times the centre that passes the centroid check.
 * Each band is narrower than its check by a billionth of the distances
 * compared, far more than the roundings of either test, so a distance the
 * band passes is one the check passes: anything else (NaN too) goes to the
 * check itself, so the answer is the check's. Radii so small or large that their
 * squares would underflow or overflow get empty bands (NaN: no distance
 * passes). */
static inline void mesh_sure_bands(double radius, double slack, double sure[3])
{
    const double within = PTR_SPHERE_VERTEX_TOLERANCE * radius + slack;
    const double margin = 1e-9 * (radius + within);
    const double near = fmax(radius - within + margin, 0.0), far = radius + within - margin;
    const double deep = fmax(3 * PTR_SPHERE_CENTROID_DEPTH * radius - 3 * slack + 3 * margin, 0.0);
    const int sane = radius + within > 1e-100 && radius + within < 1e100;
    sure[0] = sane ? near * near : NAN;
    sure[1] = sane ? far * far : NAN;
    sure[2] = sane ? deep * deep : NAN;
}

/* The sphere of bounds lo .. hi (its centre, half their largest extent),
 * whether they are round enough to be one, and its sure bands. A bound of
 * -0 counts as +0: which of two equal zeros came first is no part of the
 * sphere (nor, for the union's threads, fixed). */
static inline void mesh_fit(const double lo[3], const double hi[3], double quantum,
                            PtrMeshSphere *s, double sure[3])
{
    double extent = 0.0, smallest = HUGE_VAL;
    for (int k = 0; k < 3; k++) {
        const double low = lo[k] + 0.0, high = hi[k] + 0.0;
        s->centre[k] = 0.5 * (low + high);
        extent = fmax(extent, high - low);
        smallest = fmin(smallest, high - low);
    }
    s->radius = 0.5 * extent;
    s->is_sphere = extent > 0.0 && isfinite(extent) &&
                   smallest + 2 * quantum >= PTR_SPHERE_EXTENT_RATIO * extent;
    mesh_sure_bands(s->radius, 2 * quantum, sure);
}

static inline double mesh_squared_distance(const double a[3], const double b[3])
{
    return (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
           (a[2] - b[2]) * (a[2] - b[2]);
}

/* Whether vertex p lies off sphere s. */
static inline int mesh_vertex_off(const PtrMeshSphere *s, const double sure[3], double quantum,
                                  const double p[3])
{
    const double d2 = mesh_squared_distance(p, s->centre);
    if (d2 >= sure[0] && d2 <= sure[1])
        return 0;
    return !(fabs(sqrt(d2) - s->radius) <= PTR_SPHERE_VERTEX_TOLERANCE * s->radius + 2 * quantum);
}

/* Whether the triangle with corners a, b, c of sphere s, whose centre
 * times 3 is centre3, has its centroid too deep inside s (compared at
 * three times the scale: the corners' sum against centre3, so that nothing
 * is divided). */
static inline int mesh_centroid_off(const PtrMeshSphere *s, const double centre3[3],
                                    const double sure[3], double quantum, const double a[3],
                                    const double b[3], const double c[3])
{
    const double sum[3] = { 0.0 + a[0] + b[0] + c[0], 0.0 + a[1] + b[1] + c[1],
                            0.0 + a[2] + b[2] + c[2] };
    const double d2 = mesh_squared_distance(sum, centre3);
    return !(d2 >= sure[2]) &&
           !(sqrt(d2) + 3 * (2 * quantum) >= 3 * PTR_SPHERE_CENTROID_DEPTH * s->radius);
}

#endif /* PTR_MESH_COMPONENT_H */
