#include "accel/isect.h"

#include <assert.h>
#include <math.h>
#include <stddef.h>

#include "accel/sphere_hit.h"

/* The assembly kernels read these structures at fixed offsets (asm/layout.inc). */
static_assert(offsetof(PtrRay, tmin) == 12 && offsetof(PtrRay, dir) == 16 &&
              offsetof(PtrRay, tmax) == 28 && sizeof(PtrRay) == 32, "PtrRay layout");
static_assert(offsetof(PtrSpheres, cx) == 0 && offsetof(PtrSpheres, cy) == 8 &&
              offsetof(PtrSpheres, cz) == 16 && offsetof(PtrSpheres, radius) == 24,
              "PtrSpheres layout");
static_assert(offsetof(PtrHit, t) == 0 && offsetof(PtrHit, sphere) == 4, "PtrHit layout");
static_assert(offsetof(PtrRayPacket, tmin) == 96 && offsetof(PtrRayPacket, dir) == 128 &&
              offsetof(PtrRayPacket, tmax) == 224 && offsetof(PtrHitPacket, sphere) == 32 &&
              PTR_PACKET_LANES == 8, "PtrRayPacket and PtrHitPacket layout");

#ifndef PTR_HAVE_ASM
#define PTR_HAVE_ASM 0
#endif

#if PTR_HAVE_ASM
PTR_DECL_CLOSEST_HIT(ptr_closest_hit_sse41);
PTR_DECL_CLOSEST_HIT(ptr_closest_hit_avx2);
PTR_DECL_CLOSEST_HIT(ptr_closest_hit_avx512);
PTR_DECL_BVH_CLOSEST_HIT(ptr_bvh_closest_hit_avx2);
PTR_DECL_BVH_CLOSEST_HIT(ptr_bvh_closest_hit_avx512);
PTR_DECL_CLOSEST_HIT_PACKET(ptr_closest_hit_packet_avx2);
PTR_DECL_BVH_CLOSEST_HIT_PACKET(ptr_bvh_closest_hit_packet_avx2);
PTR_DECL_BVH_CLOSEST_HIT_PACKET(ptr_bvh_closest_hit_packet_avx512);
#endif

/* The arithmetic is ptr_sphere_hit's (sphere_hit.h), which says what the
 * assembly versions must match. */
PTR_DECL_CLOSEST_HIT(ptr_closest_hit_c)
{
    assert(count <= spheres->capacity && count < ((size_t)1 << 31));
    assert((uintptr_t)spheres->cx % PTR_SPHERE_ALIGN == 0 &&
           (uintptr_t)spheres->cy % PTR_SPHERE_ALIGN == 0 &&
           (uintptr_t)spheres->cz % PTR_SPHERE_ALIGN == 0 &&
           (uintptr_t)spheres->radius % PTR_SPHERE_ALIGN == 0);
    assert(ray->tmin >= 0.0f && ray->tmin < ray->tmax);
    float best = ray->tmax;
    uint32_t best_index = PTR_NO_HIT;
    for (size_t i = 0; i < count; i++) {
        const float t = ptr_sphere_hit(ray, spheres, i);
        if (t > ray->tmin && t < best) {
            best = t;
            best_index = (uint32_t)i;
        }
    }
    hit->t = best;
    hit->sphere = best_index;
    return best_index != PTR_NO_HIT;
}

/* Lane k of a packet as one ray, and one ray's answer as lane k's. */
static PtrRay packet_lane(const PtrRayPacket *rays, int k)
{
    return (PtrRay){ { rays->org[0][k], rays->org[1][k], rays->org[2][k] }, rays->tmin[k],
                     { rays->dir[0][k], rays->dir[1][k], rays->dir[2][k] }, rays->tmax[k] };
}

static void set_lane(PtrHitPacket *hits, int k, PtrHit hit)
{
    hits->t[k] = hit.t;
    hits->sphere[k] = hit.sphere;
}

/* Lane by lane, the one-ray references: the definitions the packet kernels
 * must match. */
PTR_DECL_CLOSEST_HIT_PACKET(ptr_closest_hit_packet_c)
{
    for (int k = 0; k < PTR_PACKET_LANES; k++) {
        const PtrRay ray = packet_lane(rays, k);
        PtrHit hit;
        ptr_closest_hit_c(&ray, spheres, count, &hit);
        set_lane(hits, k, hit);
    }
}

PTR_DECL_BVH_CLOSEST_HIT_PACKET(ptr_bvh_closest_hit_packet_c)
{
    for (int k = 0; k < PTR_PACKET_LANES; k++) {
        const PtrRay ray = packet_lane(rays, k);
        PtrHit hit;
        ptr_bvh_closest_hit_c(&ray, bvh, spheres, &hit);
        set_lane(hits, k, hit);
    }
}

void ptr_isect_init_level(PtrIsectTable *table, PtrCpuLevel level)
{
    table->closest_hit = ptr_closest_hit_c;
    table->bvh_closest_hit = ptr_bvh_closest_hit_c;
    table->closest_hit_packet = ptr_closest_hit_packet_c;
    table->bvh_closest_hit_packet = ptr_bvh_closest_hit_packet_c;
    table->name = "c";
    table->level = level;
#if PTR_HAVE_ASM
    if (level < PTR_CPU_SSE41)
        return;
    table->closest_hit = ptr_closest_hit_sse41;
    table->name = "sse41";
    if (level < PTR_CPU_AVX2)
        return;
    table->closest_hit = ptr_closest_hit_avx2;
    table->bvh_closest_hit = ptr_bvh_closest_hit_avx2;
    table->closest_hit_packet = ptr_closest_hit_packet_avx2;
    table->bvh_closest_hit_packet = ptr_bvh_closest_hit_packet_avx2;
    table->name = "avx2";
    if (level < PTR_CPU_AVX512)
        return;
    table->closest_hit = ptr_closest_hit_avx512;
    table->bvh_closest_hit = ptr_bvh_closest_hit_avx512;
    table->bvh_closest_hit_packet = ptr_bvh_closest_hit_packet_avx512;
    table->name = "avx512";
#else
    (void)level;
#endif
}

int ptr_isect_has_asm(void)
{
    return PTR_HAVE_ASM;
}

/* The narrowest level whose vector a scene of this many spheres fills:
 * 4 lanes (SSE4.1), 8 (AVX2), 16 (AVX-512). */
static PtrCpuLevel widest_useful_level(size_t sphere_count)
{
    return sphere_count <= 4 ? PTR_CPU_SSE41 : sphere_count <= 8 ? PTR_CPU_AVX2 : PTR_CPU_AVX512;
}

/* The one-ray brute-force kernel no wider than the scene; everything else
 * (packets, the tree) at the CPU's level. */
static void init_for_scene(PtrIsectTable *table, PtrCpuLevel level, size_t sphere_count)
{
    PtrCpuLevel useful = widest_useful_level(sphere_count);
    ptr_isect_init_level(table, level);
    if (level > useful) {
        PtrIsectTable narrow;
        ptr_isect_init_level(&narrow, useful);
        table->closest_hit = narrow.closest_hit;
        table->name = narrow.name;
    }
}

PtrResult ptr_isect_init(PtrIsectTable *table, PtrKernel kernel, PtrCpuLevel level,
                         size_t sphere_count, PtrError *err)
{
    if (kernel == PTR_KERNEL_C) {
        ptr_isect_init_level(table, PTR_CPU_NONE);
        return PTR_OK;
    }
    init_for_scene(table, level, sphere_count);
    if (kernel == PTR_KERNEL_ASM && table->closest_hit == ptr_closest_hit_c)
        return ptr_error_set(err, PTR_ERR_USAGE,
                             "no assembly intersector at CPU level '%s' (this build %s)",
                             ptr_cpu_level_name(level),
                             ptr_isect_has_asm() ? "has them" : "was built without them");
    return PTR_OK;
}
