/* 4x4 transforms (gltf_transforms.h). */
#include "gltf_transforms.h"

#include <math.h>
#include <string.h>

Mat4 gltf_mat4_mul(const Mat4 *a, const Mat4 *b)
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

Mat4 gltf_trs_matrix(const double translation[3], const double rotation[4],
                     const double scale[3])
{
    Mat4 r;
    const double x = rotation[0], y = rotation[1], z = rotation[2], w = rotation[3];
    const double rot[9] = {
        1 - 2 * (y * y + z * z), 2 * (x * y + z * w), 2 * (x * z - y * w),
        2 * (x * y - z * w), 1 - 2 * (x * x + z * z), 2 * (y * z + x * w),
        2 * (x * z + y * w), 2 * (y * z - x * w), 1 - 2 * (x * x + y * y),
    };
    for (int c = 0; c < 3; c++) {
        for (int row = 0; row < 3; row++)
            r.m[c * 4 + row] = rot[c * 3 + row] * scale[c];
        r.m[c * 4 + 3] = 0.0;
    }
    r.m[12] = translation[0];
    r.m[13] = translation[1];
    r.m[14] = translation[2];
    r.m[15] = 1.0;
    return r;
}

Mat4 gltf_node_local(const GltfNode *n)
{
    if (!n->has_matrix)
        return gltf_trs_matrix(n->translation, n->rotation, n->scale);
    Mat4 r;
    memcpy(r.m, n->matrix, sizeof r.m);
    return r;
}

void gltf_mat4_point(const Mat4 *a, const double p[3], double out[3])
{
    for (int row = 0; row < 3; row++)
        out[row] = a->m[row] * p[0] + a->m[4 + row] * p[1] + a->m[8 + row] * p[2] +
                   a->m[12 + row];
}

double gltf_column_length(const Mat4 *a, int c)
{
    const double *v = &a->m[c * 4];
    return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

double gltf_axis_scale(const Mat4 *world, int *nonuniform)
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
