/* What the checker's parts share: the checked call (checked_call.asm) and
 * whether it can see the YMM state. */
#ifndef PTR_CHECKASM_H
#define PTR_CHECKASM_H

#include <stddef.h>
#include <stdint.h>

#include "accel/bvh.h"
#include "accel/isect.h"

typedef struct CheckedCallStatus {
    uint32_t check_xinuse;
    uint32_t failures; /* 1: a callee-saved register changed; 2: no vzeroupper */
} CheckedCallStatus;

/* Calls fn with every callee-saved register holding a sentinel and reports
 * in status what did not survive. One routine, three signatures of 4
 * arguments. */
int ptr_checked_call(PtrClosestHitFn fn, const PtrRay *ray, const PtrSpheres *spheres,
                     size_t count, PtrHit *hit, CheckedCallStatus *status);
int ptr_checked_call_bvh(PtrBvhClosestHitFn fn, const PtrRay *ray, const PtrBvh *bvh,
                         const PtrSpheres *spheres, PtrHit *hit, CheckedCallStatus *status);

void ptr_checked_call_packet(PtrClosestHitPacketFn fn, const PtrRayPacket *rays,
                             const PtrSpheres *spheres, size_t count, PtrHitPacket *hits,
                             CheckedCallStatus *status);

/* Whether XGETBV(1) can tell a dirty upper YMM state. */
uint32_t xinuse_supported(void);

/* The tree traversal of every level against the C traversal and against
 * brute force; returns the number of levels that failed. */
int check_bvh(uint64_t seed, int *passed);

/* Nanoseconds per ray of each level's traversal on cloud scenes. */
void bench_bvh(void);

#endif
