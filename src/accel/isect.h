/* Closest-hit queries of one ray against a run of spheres.
 *
 * The kernel sits behind a function-pointer table filled once at start-up:
 * first with the portable C reference, then overridden by faster versions
 * the CPU supports. Hot code makes one indirect call and never branches on the
 * CPU. Every version returns exactly what the C reference returns.
 */
#ifndef PTR_ISECT_H
#define PTR_ISECT_H

#include <stddef.h>
#include <stdint.h>

#include "accel/bvh.h"
#include "accel/ray.h"
#include "base/cpu.h"
#include "base/result.h"
#include "scene/scene.h"

/* One signature for the pointer type, the C reference and every assembly
 * version, so that they cannot drift apart. Tests the first count spheres;
 * writes *hit in every case and returns 1 on a hit, 0 on a miss. On equal
 * distances the lowest index wins.
 *
 * Preconditions, which the C reference asserts and the SIMD versions rely on:
 * the sphere arrays are PTR_SPHERE_ALIGN-aligned and readable up to count
 * rounded up to PTR_SPHERE_BLOCK (count <= capacity), count < 2^31, and
 * 0 <= tmin < tmax with tmax not NaN. */
#define PTR_DECL_CLOSEST_HIT(name)                                            \
    int name(const PtrRay *ray, const PtrSpheres *spheres, size_t count,      \
             PtrHit *hit)

typedef PTR_DECL_CLOSEST_HIT((*PtrClosestHitFn));

/* Bundles of paths (render/bundle.c) trace their rays together: lane k of a
 * packet is one ray, and lane k of the answer is exactly what the one-ray
 * kernel answers for it. Tests the first count spheres, with the one-ray
 * kernel's preconditions in every lane. */
enum { PTR_PACKET_LANES = 8 };

typedef struct PtrRayPacket {
    _Alignas(32) float org[3][PTR_PACKET_LANES];
    float tmin[PTR_PACKET_LANES];
    float dir[3][PTR_PACKET_LANES];
    float tmax[PTR_PACKET_LANES];
} PtrRayPacket;

typedef struct PtrHitPacket {
    _Alignas(32) float t[PTR_PACKET_LANES];
    uint32_t sphere[PTR_PACKET_LANES];
} PtrHitPacket;

#define PTR_DECL_CLOSEST_HIT_PACKET(name)                                     \
    void name(const PtrRayPacket *rays, const PtrSpheres *spheres,            \
              size_t count, PtrHitPacket *hits)

typedef PTR_DECL_CLOSEST_HIT_PACKET((*PtrClosestHitPacketFn));

/* The same for the tree: lane k of the answer is exactly what
 * PTR_DECL_BVH_CLOSEST_HIT answers for lane k's ray. */
#define PTR_DECL_BVH_CLOSEST_HIT_PACKET(name)                                 \
    void name(const PtrRayPacket *rays, const PtrBvh *bvh,                    \
              const PtrSpheres *spheres, PtrHitPacket *hits)

typedef PTR_DECL_BVH_CLOSEST_HIT_PACKET((*PtrBvhClosestHitPacketFn));

typedef enum PtrKernel {
    PTR_KERNEL_AUTO, /* the fastest at the CPU level in force */
    PTR_KERNEL_C,    /* the portable reference */
    PTR_KERNEL_ASM,  /* the fastest assembly version; fails if there is none */
} PtrKernel;

typedef struct PtrIsectTable {
    PtrClosestHitFn closest_hit;
    PtrBvhClosestHitFn bvh_closest_hit;
    PtrClosestHitPacketFn closest_hit_packet;
    PtrBvhClosestHitPacketFn bvh_closest_hit_packet;
    const char *name;  /* which implementation closest_hit is: "c", "avx2", ... */
    PtrCpuLevel level; /* the CPU level the table is for (closest_hit may be
                        * narrower: see ptr_isect_init) */
} PtrIsectTable;

/* Fills the table for the requested kernel at the given CPU level (the
 * caller's: ptr_cpu_level, or lower), for scenes of sphere_count spheres: a
 * vector wider than the scene only tests padding, so the widest kernel is the
 * one the scene fills. PTR_ERR_USAGE if the requested kernel is not
 * available. */
PtrResult ptr_isect_init(PtrIsectTable *table, PtrKernel kernel, PtrCpuLevel level,
                         size_t sphere_count, PtrError *err);

/* Fills the table as a CPU of exactly this level would (for the checker and
 * for --print-dispatch). */
void ptr_isect_init_level(PtrIsectTable *table, PtrCpuLevel level);

/* Whether this build contains the assembly kernels. */
int ptr_isect_has_asm(void);

/* The reference implementations. */
PTR_DECL_CLOSEST_HIT(ptr_closest_hit_c);
PTR_DECL_CLOSEST_HIT_PACKET(ptr_closest_hit_packet_c);
PTR_DECL_BVH_CLOSEST_HIT_PACKET(ptr_bvh_closest_hit_packet_c);

#endif /* PTR_ISECT_H */
