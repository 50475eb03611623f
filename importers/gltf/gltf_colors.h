/* Spheres coloured by their vertices: textures and COLOR_0 read at each
 * component's vertices (docs/scenes.md, "Textures"). */
#ifndef PTR_GLTF_COLORS_H
#define PTR_GLTF_COLORS_H

#include "gltf_importer.h"
#include "gltf_parts.h"
#include "mesh_spheres.h"

/* Whether a primitive's spheres take their colours from its vertices: its
 * material's textures (where the import reads them) or its COLOR_0. */
int gltf_colored_by_vertices(const Importer *im, const GltfPrimitive *prim);

/* Each sphere's own material (out->materials) where its vertices colour it:
 * labels give each vertex's component among found. */
PtrResult gltf_surface_colors(Importer *im, const Origin *o, size_t mesh_index,
                              const SurfaceParts *s, const PtrMeshSphere *found,
                              size_t components, const uint32_t *labels, SurfaceSpheres *out);

#endif /* PTR_GLTF_COLORS_H */
