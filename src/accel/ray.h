/* A ray and the answer to a closest-hit query: shared by the brute-force
 * kernels (isect.h) and the tree (bvh.h). */
#ifndef PTR_RAY_H
#define PTR_RAY_H

#include <stdint.h>

/* A ray with a unit direction; hits count only for tmin < t < tmax.
 * Layout is fixed (32 bytes) because assembly kernels read it. */
typedef struct PtrRay {
    float org[3];
    float tmin;
    float dir[3];
    float tmax;
} PtrRay;

typedef struct PtrHit {
    float t;         /* ray->tmax on a miss */
    uint32_t sphere; /* PTR_NO_HIT on a miss */
} PtrHit;

#define PTR_NO_HIT UINT32_MAX

#endif /* PTR_RAY_H */
