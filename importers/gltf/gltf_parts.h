/* A mesh's surface primitives as one mesh for mesh_spheres.h: each a part
 * of its vertices and triangles, checked. */
#ifndef PTR_GLTF_PARTS_H
#define PTR_GLTF_PARTS_H

#include "gltf_importer.h"

/* A surface primitive's part of its mesh's vertices and triangles. */
typedef struct SurfacePart {
    GltfAccessor pos, idx; /* idx read where has_idx says */
    int has_idx, mode, primitive;
    size_t first_vertex, first_triangle, triangles;
} SurfacePart;

typedef struct SurfaceParts {
    SurfacePart *parts;
    size_t count;
} SurfaceParts;

/* The part holding vertex or triangle `at` (by_triangle), parts in order. */
const SurfacePart *gltf_part_of(const SurfaceParts *s, size_t at, int by_triangle);

/* The PtrMeshSource readers (mesh_spheres.h) of the parts a SurfaceParts
 * (user) holds. */
void gltf_mesh_positions(const void *user, size_t first, size_t count, double (*out)[3]);

void gltf_mesh_gather(const void *user, const uint32_t *vertices, size_t count,
                      double (*out)[3]);

void gltf_mesh_triangles(const void *user, size_t first, size_t count, uint32_t (*out)[3]);

/* The step of a position accessor's storage (mesh_spheres.h). */
double gltf_position_quantum(const GltfAccessor *a);

/* Primitive p of mesh as a surface part, checked: its positions, its
 * indices and that they are in range. Lines (and fewer than 3 corners) give
 * no triangles: part->triangles 0. part->first_vertex holds its vertex
 * count until the mesh's parts are placed one after another. */
PtrResult gltf_surface_part(Importer *im, const Origin *o, size_t mesh, size_t p,
                            const GltfPrimitive *prim, SurfacePart *part);

#endif /* PTR_GLTF_PARTS_H */
