/* The spheres of a mesh's surface (docs/scenes.md, "What becomes a sphere"): one a
 * connected component, found once for meshes of the same surface. */
#ifndef PTR_GLTF_SURFACES_H
#define PTR_GLTF_SURFACES_H

#include "gltf_importer.h"

/* The spheres of mesh_index's surface, found at the first node using it
 * (o); the node's extras.radius aside, which needs none. */
PtrResult gltf_surface_spheres(Importer *im, const Origin *o, size_t mesh_index,
                               const SurfaceSpheres **out);

/* Notes a node's mesh parts that are not spheres for the file's warning. */
void gltf_note_skipped(Importer *im, const Origin *o, const GltfMesh *mesh, size_t parts);

#endif /* PTR_GLTF_SURFACES_H */
