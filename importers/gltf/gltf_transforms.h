/* The 4x4 affine transforms of glTF's nodes and instances. */
#ifndef PTR_GLTF_TRANSFORMS_H
#define PTR_GLTF_TRANSFORMS_H

#include "gltf_doc.h"

/* 4x4 affine transforms, column-major like glTF: m[column * 4 + row]. */
typedef struct Mat4 {
    double m[16];
} Mat4;

/* a * b: b's transform, then a's. */
Mat4 gltf_mat4_mul(const Mat4 *a, const Mat4 *b);

/* T * R * S, as glTF composes a node's TRS properties (rotation a unit
 * quaternion x, y, z, w). */
Mat4 gltf_trs_matrix(const double translation[3], const double rotation[4],
                     const double scale[3]);

/* A node's own transform: its matrix, or its TRS. */
Mat4 gltf_node_local(const GltfNode *n);

/* Point p under a. */
void gltf_mat4_point(const Mat4 *a, const double p[3], double out[3]);

/* The length of a's column c: the scale of axis c. */
double gltf_column_length(const Mat4 *a, int c);

/* The largest of world's axis scales; *nonuniform set if they differ. */
double gltf_axis_scale(const Mat4 *world, int *nonuniform);

#endif /* PTR_GLTF_TRANSFORMS_H */
