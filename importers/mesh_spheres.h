/* The spheres a triangle mesh holds: its connected components, each fitted
 * with a sphere and checked to be one (docs/scenes.md, "What becomes a sphere"). */
#ifndef PTR_MESH_SPHERES_H
#define PTR_MESH_SPHERES_H

#include "base/result.h"
#include "mesh_component.h"

/* The mesh's components (triangles sharing a vertex, by index or by equal
 * position), in the order of their first triangles, into *out (malloc'd,
 * the caller frees it) and *count. Vertices no triangle uses are ignored.
 * Where vertex_spheres is not NULL, *vertex_spheres receives each vertex's
 * component, as its index in *out (UINT32_MAX for a vertex no triangle
 * uses), malloc'd too: what a reader of per-vertex colours needs. Fails
 * only for memory (PTR_ERR_NOMEM, naming path). */
PtrResult ptr_mesh_spheres(const PtrMeshSource *mesh, const char *path, PtrMeshSphere **out,
                           size_t *count, uint32_t **vertex_spheres, PtrError *err);

/* The same, always found by the union over the whole mesh: the reference
 * that ptr_mesh_spheres's run-by-run way (mesh_runs.h), where it applies,
 * matches to the bit. */
PtrResult ptr_mesh_spheres_by_union(const PtrMeshSource *mesh, const char *path,
                                    PtrMeshSphere **out, size_t *count,
                                    uint32_t **vertex_spheres, PtrError *err);

#endif /* PTR_MESH_SPHERES_H */
