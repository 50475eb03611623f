/* 4x4 transforms (gltf_transforms.h). */
#include "gltf_transforms.h"

#include <string.h>

Mat4 gltf_node_local(const GltfNode *n)
{
    if (!n->has_matrix)
        return gltf_trs_matrix(n->translation, n->rotation, n->scale);
    Mat4 r;
    memcpy(r.m, n->matrix, sizeof r.m);
    return r;
}

