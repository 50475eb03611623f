/* A mesh's components found run by run, where its triangles fall into runs
 * over ranges of vertices of their own: what joined meshes are. */
#ifndef PTR_MESH_RUNS_H
#define PTR_MESH_RUNS_H

#include "base/result.h"
#include "mesh_component.h"

/* As ptr_mesh_spheres, on threads threads, where the mesh lies in runs of
 * closed surfaces by index (mesh_runs.c says what that is): *found is then
 * 1 and the result is ptr_mesh_spheres_by_union's to the bit; else *found
 * is 0 and nothing is handed back. Fails only for memory. */
PtrResult ptr_mesh_spheres_by_runs(const PtrMeshSource *mesh, int threads, const char *path,
                                   PtrMeshSphere **out, size_t *count,
                                   uint32_t **vertex_spheres, int *found, PtrError *err);

#endif /* PTR_MESH_RUNS_H */
