/* The 4x4 affine transforms of glTF's nodes and instances. */
#ifndef PTR_GLTF_TRANSFORMS_H
#define PTR_GLTF_TRANSFORMS_H

#include <math.h>

#include "gltf_doc.h"

/* 4x4 affine transforms, column-major like glTF: m[column * 4 + row]. The
 * arithmetic is inline, for it runs once an instance: called, each result
 * went through memory, and its reader stalled on the stores. */
typedef struct Mat4 {
    double m[16];
} Mat4;

/* a * b: b's transform, then a's. */
static inline Mat4 gltf_mat4_mul(const Mat4 *a, const Mat4 *b)
{
    Mat4 r;
    for (int c = 0; c < 4; c++)
        for (int row = 0; row < 4; row++) {
            double sum = 0.0;
            for (int k = 0; k < 4; k++)
                sum += a->m[k * 4 + row] * b->m[c * 4 + k];
            r.m[c * 4 + row] = sum;
        }
    return r;
}

/* Whether a is the identity (a zero of either sign counting as 0). */
static inline int gltf_mat4_is_identity(const Mat4 *a)
{
    for (int k = 0; k < 16; k++)
        if (a->m[k] != (k % 5 == 0 ? 1.0 : 0.0)) /* entries 0, 5, 10, 15: the diagonal */
            return 0;
    return 1;
}

/* gltf_mat4_mul(a, b) for an identity a and a finite b, without its 64
 * products: each entry of b plus 0.0, the same bits. gltf_mat4_mul sums an
 * entry from +0.0 in k's order. Its terms before b's entry are zeros (a zero
 * of a times a finite entry of b: +0 or -0), and +0.0 plus a zero of either
 * sign is +0. Then 1 times b's entry, exact, is added: b's entry, or +0 for
 * a -0. The terms after are zeros again, which change neither a nonzero sum
 * nor a +0. So the sum is b's entry with -0 made +0, as adding 0.0 makes it.
 * (IEEE arithmetic rounding to nearest, subnormals kept: ptr never changes
 * either.) */
static inline Mat4 gltf_mat4_identity_mul(const Mat4 *b)
{
    Mat4 r;
    for (int k = 0; k < 16; k++)
        r.m[k] = b->m[k] + 0.0;
    return r;
}

/* T * R * S, as glTF composes a node's TRS properties (rotation a unit
 * quaternion x, y, z, w). */
static inline Mat4 gltf_trs_matrix(const double translation[3], const double rotation[4],
                                   const double scale[3])
{
    const double x = rotation[0], y = rotation[1], z = rotation[2], w = rotation[3];
    /* Written straight into the matrix: built in a 3x3 array of the
     * rotation first, it went through memory even inline. */
    const Mat4 r = { {
        (1 - 2 * (y * y + z * z)) * scale[0], 2 * (x * y + z * w) * scale[0],
        2 * (x * z - y * w) * scale[0], 0.0,
        2 * (x * y - z * w) * scale[1], (1 - 2 * (x * x + z * z)) * scale[1],
        2 * (y * z + x * w) * scale[1], 0.0,
        2 * (x * z + y * w) * scale[2], 2 * (y * z - x * w) * scale[2],
        (1 - 2 * (x * x + y * y)) * scale[2], 0.0,
        translation[0], translation[1], translation[2], 1.0,
    } };
    return r;
}

/* A node's own transform: its matrix, or its TRS. */
Mat4 gltf_node_local(const GltfNode *n);

/* Point p under a. */
static inline void gltf_mat4_point(const Mat4 *a, const double p[3], double out[3])
{
    for (int row = 0; row < 3; row++)
        out[row] = a->m[row] * p[0] + a->m[4 + row] * p[1] + a->m[8 + row] * p[2] +
                   a->m[12 + row];
}

/* The length of a's column c: the scale of axis c. */
static inline double gltf_column_length(const Mat4 *a, int c)
{
    const double *v = &a->m[c * 4];
    return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

/* The largest of world's axis scales; *nonuniform set if they differ. */
static inline double gltf_axis_scale(const Mat4 *world, int *nonuniform)
{
    double scale[3] = { gltf_column_length(world, 0), gltf_column_length(world, 1),
                        gltf_column_length(world, 2) };
    /* Not fmin and fmax, library calls here: lengths are never NaN. */
    double smin = scale[0], smax = scale[0];
    for (int k = 1; k < 3; k++) {
        smin = scale[k] < smin ? scale[k] : smin;
        smax = scale[k] > smax ? scale[k] : smax;
    }
    if (smax - smin > 1e-6 * smax)
        *nonuniform = 1;
    return smax;
}

#endif /* PTR_GLTF_TRANSFORMS_H */
