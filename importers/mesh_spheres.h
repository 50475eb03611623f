/* The spheres a triangle mesh holds: its connected components, each fitted
 * with a sphere and checked to be one (docs/scenes.md, "Spheres"). */
#ifndef PTR_MESH_SPHERES_H
#define PTR_MESH_SPHERES_H

#include <stddef.h>
#include <stdint.h>

#include "base/result.h"

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

/* The mesh's components (triangles sharing a vertex, by index or by equal
 * position), in the order of their first triangles, into *out (malloc'd,
 * the caller frees it) and *count. Vertices no triangle uses are ignored.
 * Where vertex_spheres is not NULL, *vertex_spheres receives each vertex's
 * component, as its index in *out (UINT32_MAX for a vertex no triangle
 * uses), malloc'd too: what a reader of per-vertex colours needs. Fails
 * only for memory (PTR_ERR_NOMEM, naming path). */
PtrResult ptr_mesh_spheres(const PtrMeshSource *mesh, const char *path, PtrMeshSphere **out,
                           size_t *count, uint32_t **vertex_spheres, PtrError *err);

#endif /* PTR_MESH_SPHERES_H */
