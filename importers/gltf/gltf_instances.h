/* A node's spheres: its surface's and its points', once per instance of
 * EXT_mesh_gpu_instancing, on all cores for a large node. */
#ifndef PTR_GLTF_INSTANCES_H
#define PTR_GLTF_INSTANCES_H

#include "gltf_importer.h"
#include "gltf_transforms.h"

/* The node's spheres (see NodeRun in gltf_instances.c): what they share checked first, as a
 * serial import meets it at the first instance. */
PtrResult gltf_add_node_spheres(Importer *im, size_t node_index, const GltfNode *node,
                                const Mat4 *world);

#endif /* PTR_GLTF_INSTANCES_H */
