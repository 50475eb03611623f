/* Three-component single-precision vectors, used for points, directions and
 * colours alike. Everything is inline: these sit on the hot path. */
#ifndef PTR_VEC_H
#define PTR_VEC_H

#include <math.h>

#define PTR_PI 3.14159265358979323846f

/* Minimum and maximum for numbers known not to be NaN: unlike fminf/fmaxf,
 * which strict C makes library calls, these compile to one instruction. */
static inline float ptr_minf(float a, float b) { return a < b ? a : b; }
static inline float ptr_maxf(float a, float b) { return a > b ? a : b; }

typedef struct PtrVec3 {
    float x, y, z;
} PtrVec3;

static inline PtrVec3 v3(float x, float y, float z) { return (PtrVec3){ x, y, z }; }
static inline PtrVec3 v3_splat(float s) { return (PtrVec3){ s, s, s }; }
static inline PtrVec3 v3_add(PtrVec3 a, PtrVec3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline PtrVec3 v3_sub(PtrVec3 a, PtrVec3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline PtrVec3 v3_mul(PtrVec3 a, PtrVec3 b) { return v3(a.x * b.x, a.y * b.y, a.z * b.z); }
static inline PtrVec3 v3_scale(PtrVec3 a, float s) { return v3(a.x * s, a.y * s, a.z * s); }
static inline PtrVec3 v3_neg(PtrVec3 a) { return v3(-a.x, -a.y, -a.z); }
static inline float v3_dot(PtrVec3 a, PtrVec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline float v3_length(PtrVec3 a) { return sqrtf(v3_dot(a, a)); }
static inline float v3_max_abs(PtrVec3 a) { return ptr_maxf(fabsf(a.x), ptr_maxf(fabsf(a.y), fabsf(a.z))); }
static inline float v3_max_comp(PtrVec3 a) { return ptr_maxf(a.x, ptr_maxf(a.y, a.z)); }

/* a + b * s */
static inline PtrVec3 v3_madd(PtrVec3 a, PtrVec3 b, float s)
{
    return v3(a.x + b.x * s, a.y + b.y * s, a.z + b.z * s);
}

static inline PtrVec3 v3_cross(PtrVec3 a, PtrVec3 b)
{
    return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}

static inline PtrVec3 v3_normalize(PtrVec3 a)
{
    return v3_scale(a, 1.0f / v3_length(a));
}

#endif /* PTR_VEC_H */
