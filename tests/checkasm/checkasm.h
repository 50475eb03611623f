/* What the checker's parts share. checkasm.c is the harness: the generated
 * cases, the run and the report. Each field of the kernel tables
 * (accel/isect.h, denoise/conv.h) is checked in the file named after it:
 * closest_hit.c, closest_hit_packet.c, bvh_closest_hit.c,
 * bvh_closest_hit_packet.c, conv3x3.c; and the build's binning
 * (accel/bvh_split.h) in bvh_bin.c. */
#ifndef PTR_CHECKASM_H
#define PTR_CHECKASM_H

#include <stddef.h>
#include <stdint.h>

#include "accel/bvh.h"
#include "accel/isect.h"
#include "base/cpu.h"
#include "denoise/conv.h"
#include "sampling/rng.h"
#include "scene/scene.h"

typedef struct CheckedCallStatus {
    uint32_t check_xinuse;
    uint32_t failures; /* 1: a callee-saved register changed; 2: no vzeroupper */
} CheckedCallStatus;

/* Calls fn with every callee-saved register holding a sentinel and reports
 * in status what did not survive. One routine, four signatures of 4
 * arguments. */
int ptr_checked_call(PtrClosestHitFn fn, const PtrRay *ray, const PtrSpheres *spheres,
                     size_t count, PtrHit *hit, CheckedCallStatus *status);
int ptr_checked_call_bvh(PtrBvhClosestHitFn fn, const PtrRay *ray, const PtrBvh *bvh,
                         const PtrSpheres *spheres, PtrHit *hit, CheckedCallStatus *status);

void ptr_checked_call_packet(PtrClosestHitPacketFn fn, const PtrRayPacket *rays,
                             const PtrSpheres *spheres, size_t count, PtrHitPacket *hits,
                             CheckedCallStatus *status);
void ptr_checked_call_bvh_packet(PtrBvhClosestHitPacketFn fn, const PtrRayPacket *rays,
                                 const PtrBvh *bvh, const PtrSpheres *spheres,
                                 PtrHitPacket *hits, CheckedCallStatus *status);

/* A convolution's nine arguments (PTR_DECL_CONV3X3), in order, for the
 * checked call to pass on. */
typedef struct ConvCall {
    float *dst;
    const float *src, *weights, *bias;
    size_t width, rows, in_channels, out_channels;
    int relu;
} ConvCall;
void ptr_checked_call_conv3x3(PtrConv3x3Fn fn, const ConvCall *call, CheckedCallStatus *status);

/* Whether XGETBV(1) can tell a dirty upper YMM state. */
uint32_t xinuse_supported(void);

/* Ends a kernel's line of the result with what the checked calls saw. */
void print_status(const CheckedCallStatus *status);

/* A generated case for the brute-force kernels: a ray and the spheres it is
 * tested against. */
typedef struct Case {
    PtrScene scene;
    PtrRay ray;
    size_t count; /* spheres tested: at most scene.spheres.count */
} Case;

/* Sets the case's ray: from o along d (normalized here), with a random tmin
 * and tmax (0 and infinity most often). */
void set_ray(Case *c, PtrVec3 o, PtrVec3 d, PtrRng *rng);

float uniform(PtrRng *rng, float lo, float hi);
PtrVec3 random_unit(PtrRng *rng);

/* Seconds on the monotonic clock. */
double now(void);

/* What the checks of one table field have seen, level by level. */
typedef struct Tally {
    uint64_t hits; /* of the C reference */
    uint64_t mismatches[PTR_CPU_LEVEL_COUNT];
    CheckedCallStatus status[PTR_CPU_LEVEL_COUNT];
} Tally;

/* closest_hit.c: every level's closest_hit against ptr_closest_hit_c on case
 * number ray_index, and their times at 4 to 512 spheres. tables is indexed
 * by level, from PTR_CPU_SSE41 to top. */
void check_closest_hit(const PtrIsectTable *tables, PtrCpuLevel top, const Case *c,
                       uint64_t ray_index, Tally *tally);
void bench_closest_hit(void);

/* closest_hit_packet.c: every level's closest_hit_packet against
 * ptr_closest_hit_packet_c, on eight rays drawn around the case. */
void check_closest_hit_packet(const PtrIsectTable *tables, PtrCpuLevel top, const Case *c,
                              PtrRng *rng, Tally *tally);

/* bvh_closest_hit.c: the tree traversal of every level against the C
 * traversal and against brute force; returns the number of levels that
 * failed. Then nanoseconds per ray of each level's traversal on clouds. */
int check_bvh_closest_hit(uint64_t seed, int *passed);

/* bvh_closest_hit_packet.c: every level's bvh_closest_hit_packet against
 * ptr_bvh_closest_hit_packet_c on one scene's tree, with packets of eight
 * rays drawn by draw (bvh_closest_hit.c's), unrelated and coherent ones;
 * returns the packets checked. */
typedef PtrRay (*DrawRayFn)(const PtrSpheres *s, PtrRng *rng);
uint64_t check_bvh_closest_hit_packet(const PtrIsectTable *tables, PtrCpuLevel top,
                                      const PtrBvh *bvh, const PtrSpheres *s, DrawRayFn draw,
                                      PtrRng *rng, Tally *tally);
void report_bvh_closest_hit_packet(const PtrIsectTable *tables, PtrCpuLevel top,
                                   uint64_t packets, const Tally *tally, int *passed,
                                   int *failed);
void bench_bvh_closest_hit(void);

/* conv3x3.c: every level's conv3x3 against ptr_conv3x3_c, bit for bit, with
 * the output's surroundings guarded; returns the number of levels that
 * failed. */
int check_conv3x3(uint64_t seed, int *passed);

/* bvh_bin.c: every level's binning for the tree's build against
 * bvh_bin_c, bit for bit, with the bins past a candidate's guarded;
 * returns the number of kernels that failed. */
int check_bvh_bin(uint64_t seed, int *passed);

#endif
