/* The closest-hit query alone, ptr against Embree 3 on identical rays: the
 * rays a render of the scene asks (camera, scattered and shadow rays, in the
 * order the integrator asks them), recorded, then answered again by every
 * one-ray traversal ptr's dispatch ladder has on this CPU, by this CPU's
 * table as the renderer asked it ("as asked": packets of eight where it
 * asked for packets), and by Embree's rtcIntersect1 and rtcIntersect16 over
 * the same spheres. One thread each, so
 * the figures are per core; runs alternate, and the best of them is printed.
 *
 *   query SCENE SPP [RUNS [METHOD]]
 *
 * Prints, per method: Mrays/s, nanoseconds and cycles per ray (of the time
 * stamp counter), all of the thread's CPU time, and the ratio to Embree's
 * best. Embree's answers are checked against ptr's (hit or
 * miss, and the same t to 1e-4 relative): its arithmetic is not ptr's, so a
 * few grazing rays may disagree, and their count is printed.
 *
 * METHOD (a name of the table, "avx512", "embree user 16"...) times that one
 * alone, for a profile (bench/stages.sh); Embree's trees are built only for
 * its own methods (at 10^8 spheres they take gigabytes).
 *
 * METHOD "warmed" splits the one-ray traversal of this CPU's table three
 * ways instead, each ray timed alone (fenced rdtsc, whose own cost is in
 * all three): cold, as the renderer meets it; right after the C reference
 * answered the same ray (its nodes and spheres in the cache, but this
 * traversal's branches not trained on its path); and right after this
 * traversal itself answered it (cache and branches warm). Cold minus the
 * second is about the wait on memory; the second minus the third about
 * the mispredicted branches; the third is the steps' work. About: the C
 * reference may visit a few other nodes, in another order, and its own
 * branches move the predictor's history.
 *
 * Embree's geometries: its own spheres (RTC_GEOMETRY_TYPE_SPHERE_POINT, what
 * ../shared/peers/embree_pt.c traces with -m 1), and user geometry whose
 * intersection is ptr's sphere arithmetic (the peer's -g user): Embree's
 * tree with ptr's leaves. */
#include <embree3/rtcore.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <x86intrin.h>

#include "accel/accel.h"
#include "accel/sphere_hit.h"
#include "base/cpu.h"
#include "importer.h"
#include "render/render.h"

/* Embree 3's C interface declares its structures without typedefs. */
typedef struct RTCIntersectContext RTCIntersectContext;
typedef struct RTCRayHit RTCRayHit;
typedef struct RTCRayHit16 RTCRayHit16;

enum { RAYS_MAX = 1 << 24, PACKET = 16 };

/* The rays a render asks, in order: the recording wraps the table's tree
 * traversals, which every query of a scene without huge spheres reaches,
 * and marks the first ray of each packet of eight the renderer asked
 * together (a pixel's camera rays). */
static PtrRay *recorded;
static uint8_t *packet_start;
static size_t recorded_count;
static PtrIsectTable recorded_table;

static PTR_DECL_BVH_CLOSEST_HIT(record_ray)
{
    if (recorded_count < RAYS_MAX) {
        packet_start[recorded_count] = 0;
        recorded[recorded_count++] = *ray;
    }
    return recorded_table.bvh_closest_hit(ray, bvh, spheres, hit);
}

static PTR_DECL_BVH_CLOSEST_HIT_PACKET(record_packet)
{
    for (int k = 0; k < PTR_PACKET_LANES && recorded_count < RAYS_MAX; k++) {
        packet_start[recorded_count] = k == 0;
        recorded[recorded_count++] = (PtrRay){ { rays->org[0][k], rays->org[1][k], rays->org[2][k] },
                                               rays->tmin[k],
                                               { rays->dir[0][k], rays->dir[1][k], rays->dir[2][k] },
                                               rays->tmax[k] };
    }
    recorded_table.bvh_closest_hit_packet(rays, bvh, spheres, hits);
}

typedef enum MethodKind {
    PTR_ONE_RAY,  /* one ray at a time through a traversal of the ladder */
    PTR_AS_ASKED, /* the table as the renderer asked it */
    EMBREE_POINT_1, EMBREE_POINT_16, EMBREE_USER_1, EMBREE_USER_16,
} MethodKind;

typedef struct Method {
    const char *name;
    MethodKind kind;
    PtrBvhClosestHitFn traversal; /* PTR_ONE_RAY's */
    double seconds;  /* the best run's, over all rays */
    double checksum; /* sum of the hits' t, to keep every query alive */
} Method;

static void keep_best(Method *m, double seconds, double checksum)
{
    if (m->seconds == 0 || seconds < m->seconds)
        m->seconds = seconds;
    m->checksum = checksum;
}

/* The calling thread's CPU time: on a shared machine, time spent waiting
 * for a core does not count. */
static double thread_seconds(void)
{
    struct timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Time stamp counter ticks a second, for cycles per ray (at the counter's
 * constant rate, whatever the core's clock did). */
static double tsc_hz(void)
{
    const double t0 = ptr_now_seconds();
    const uint64_t c0 = __rdtsc();
    while (ptr_now_seconds() - t0 < 0.05)
        ;
    return (double)(__rdtsc() - c0) / (ptr_now_seconds() - t0);
}

static void time_ptr(Method *m, const PtrAccel *accel, PtrBvhClosestHitFn traversal)
{
    double sum = 0;
    const double t0 = thread_seconds();
    for (size_t i = 0; i < recorded_count; i++) {
        PtrHit hit;
        if (traversal(&recorded[i], &accel->bvh, accel->spheres, &hit))
            sum += hit.t;
    }
    keep_best(m, thread_seconds() - t0, sum);
}

/* The rays as the renderer asked them of the table: packets of eight where
 * it asked for packets, else one by one. */
static void time_ptr_as_asked(Method *m, const PtrAccel *accel, const PtrIsectTable *table)
{
    double sum = 0;
    const double t0 = thread_seconds();
    for (size_t i = 0; i < recorded_count;) {
        if (packet_start[i] && i + PTR_PACKET_LANES <= recorded_count) {
            PtrRayPacket rays;
            for (int k = 0; k < PTR_PACKET_LANES; k++) {
                const PtrRay *r = &recorded[i + (size_t)k];
                for (int a = 0; a < 3; a++) {
                    rays.org[a][k] = r->org[a];
                    rays.dir[a][k] = r->dir[a];
                }
                rays.tmin[k] = r->tmin;
                rays.tmax[k] = r->tmax;
            }
            PtrHitPacket hits;
            table->bvh_closest_hit_packet(&rays, &accel->bvh, accel->spheres, &hits);
            for (int k = 0; k < PTR_PACKET_LANES; k++)
                sum += hits.sphere[k] != PTR_NO_HIT ? hits.t[k] : 0.0f;
            i += PTR_PACKET_LANES;
        } else {
            PtrHit hit;
            if (table->bvh_closest_hit(&recorded[i], &accel->bvh, accel->spheres, &hit))
                sum += hit.t;
            i++;
        }
    }
    keep_best(m, thread_seconds() - t0, sum);
}

/* "warmed" (see the head): nanoseconds a ray of traversal cold, after the
 * C reference answered the ray, and after the traversal itself did, each
 * the best of runs. */
static void print_warmed(const PtrAccel *accel, PtrBvhClosestHitFn reference,
                         PtrBvhClosestHitFn traversal, int runs, double hz)
{
    enum { WAYS = 3 };
    static const char *const way_name[WAYS] = { "cold", "after the C reference",
                                                "after itself" };
    const PtrBvhClosestHitFn warm_with[WAYS] = { NULL, reference, traversal };
    uint64_t best[WAYS] = { UINT64_MAX, UINT64_MAX, UINT64_MAX };
    double sum = 0; /* of the timed answers' t, printed: the answers are used */
    for (int run = 0; run < runs; run++) {
        for (int way = 0; way < WAYS; way++) {
            uint64_t ticks = 0;
            for (size_t i = 0; i < recorded_count; i++) {
                PtrHit hit;
                if (warm_with[way])
                    (void)warm_with[way](&recorded[i], &accel->bvh, accel->spheres, &hit);
                _mm_lfence();
                const uint64_t t0 = __rdtsc();
                _mm_lfence();
                if (traversal(&recorded[i], &accel->bvh, accel->spheres, &hit))
                    sum += hit.t;
                _mm_lfence();
                ticks += __rdtsc() - t0;
            }
            if (ticks < best[way])
                best[way] = ticks;
        }
    }
    printf("%-22s %9s %11s (checksum %.9g)\n", "one ray, timed alone", "ns/ray", "cycles/ray",
           sum);
    for (int way = 0; way < WAYS; way++)
        printf("%-22s %9.1f %11.0f\n", way_name[way],
               (double)best[way] / hz / (double)recorded_count * 1e9,
               (double)best[way] / (double)recorded_count);
}

static void to_embree(const PtrRay *r, RTCRayHit *rh)
{
    memset(rh, 0, sizeof *rh);
    rh->ray.org_x = r->org[0], rh->ray.org_y = r->org[1], rh->ray.org_z = r->org[2];
    rh->ray.dir_x = r->dir[0], rh->ray.dir_y = r->dir[1], rh->ray.dir_z = r->dir[2];
    rh->ray.tnear = r->tmin, rh->ray.tfar = r->tmax, rh->ray.mask = UINT32_MAX;
    rh->hit.geomID = RTC_INVALID_GEOMETRY_ID;
}

/* Times rtcIntersect1; with hits, stores each ray's t (or NAN on a miss). */
static void time_embree1(Method *m, RTCScene scene, float *hits)
{
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    double sum = 0;
    const double t0 = thread_seconds();
    for (size_t i = 0; i < recorded_count; i++) {
        RTCRayHit rh;
        to_embree(&recorded[i], &rh);
        rtcIntersect1(scene, &context, &rh);
        if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID)
            sum += rh.ray.tfar;
        if (hits)
            hits[i] = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID ? rh.ray.tfar : NAN;
    }
    keep_best(m, thread_seconds() - t0, sum);
}

/* Times rtcIntersect16 over runs of 16 consecutive rays: the bundles
 * integrator asks eight paths' rays together, so neighbours are often
 * coherent, the case where packets pay. */
static void time_embree16(Method *m, RTCScene scene)
{
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    double sum = 0;
    const double t0 = thread_seconds();
    for (size_t i = 0; i < recorded_count; i += PACKET) {
        _Alignas(64) RTCRayHit16 rh;
        _Alignas(64) int valid[PACKET];
        memset(&rh, 0, sizeof rh);
        for (int k = 0; k < PACKET; k++) {
            const size_t j = i + (size_t)k;
            valid[k] = j < recorded_count ? -1 : 0;
            const PtrRay *r = &recorded[j < recorded_count ? j : i];
            rh.ray.org_x[k] = r->org[0], rh.ray.org_y[k] = r->org[1], rh.ray.org_z[k] = r->org[2];
            rh.ray.dir_x[k] = r->dir[0], rh.ray.dir_y[k] = r->dir[1], rh.ray.dir_z[k] = r->dir[2];
            rh.ray.tnear[k] = r->tmin, rh.ray.tfar[k] = r->tmax, rh.ray.mask[k] = UINT32_MAX;
            rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
        }
        rtcIntersect16(valid, scene, &context, &rh);
        for (int k = 0; k < PACKET; k++)
            if (valid[k] && rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID)
                sum += rh.ray.tfar[k];
    }
    keep_best(m, thread_seconds() - t0, sum);
}

/* User geometry: ptr's spheres, bounds and arithmetic under Embree's tree. */
static void user_bounds(const struct RTCBoundsFunctionArguments *args)
{
    const PtrSpheres *s = args->geometryUserPtr;
    const unsigned i = args->primID;
    *args->bounds_o = (struct RTCBounds){ s->cx[i] - s->radius[i], s->cy[i] - s->radius[i],
                                   s->cz[i] - s->radius[i], 0, s->cx[i] + s->radius[i],
                                   s->cy[i] + s->radius[i], s->cz[i] + s->radius[i], 0 };
}

/* A ray-hit packet of N lanes is N-lane arrays of floats and ints in the
 * order of struct RTCRayHit: its C interface has no accessors (C++ does). */
enum { ORG_X, ORG_Y, ORG_Z, TNEAR, DIR_X, DIR_Y, DIR_Z, TIME, TFAR, MASK, RAY_ID, FLAGS,
       NG_X, NG_Y, NG_Z, HIT_U, HIT_V, PRIM_ID, GEOM_ID, INST_ID };

static void user_intersect(const struct RTCIntersectFunctionNArguments *args)
{
    const PtrSpheres *s = args->geometryUserPtr;
    const unsigned n = args->N;
    float *f = (float *)args->rayhit;
    unsigned *u = (unsigned *)args->rayhit;
    for (unsigned k = 0; k < n; k++) {
        if (!args->valid[k])
            continue;
        PtrRay ray = { { f[ORG_X * n + k], f[ORG_Y * n + k], f[ORG_Z * n + k] }, f[TNEAR * n + k],
                       { f[DIR_X * n + k], f[DIR_Y * n + k], f[DIR_Z * n + k] }, f[TFAR * n + k] };
        const float t = ptr_sphere_hit(&ray, s, args->primID);
        if (!(t > ray.tmin && t < ray.tmax))
            continue;
        f[TFAR * n + k] = t;
        u[PRIM_ID * n + k] = args->primID;
        u[GEOM_ID * n + k] = args->geomID;
        u[INST_ID * n + k] = RTC_INVALID_GEOMETRY_ID;
    }
}

static RTCScene embree_scene(RTCDevice device, const PtrSpheres *s, size_t count, int user)
{
    RTCScene scene = rtcNewScene(device);
    RTCGeometry g;
    if (user) {
        g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
        rtcSetGeometryUserPrimitiveCount(g, (unsigned)count);
        rtcSetGeometryUserData(g, (void *)s);
        rtcSetGeometryBoundsFunction(g, user_bounds, NULL);
        rtcSetGeometryIntersectFunction(g, user_intersect);
    } else {
        g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
        float *v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4,
                                           4 * sizeof(float), count);
        for (size_t i = 0; i < count; i++) {
            v[4 * i] = s->cx[i], v[4 * i + 1] = s->cy[i], v[4 * i + 2] = s->cz[i];
            v[4 * i + 3] = s->radius[i];
        }
    }
    rtcCommitGeometry(g);
    rtcAttachGeometry(scene, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(scene);
    return scene;
}

/* Every one-ray traversal of the ladder up to this CPU's level, each named
 * by the lowest level that has it (a level that keeps the level below's is
 * left out), into methods; returns their count, this CPU's traversal last. */
static int ladder_methods(Method *methods)
{
    int n = 0;
    PtrBvhClosestHitFn last = NULL;
    for (int level = PTR_CPU_NONE; level <= (int)ptr_cpu_level(); level++) {
        PtrIsectTable table;
        ptr_isect_init_level(&table, (PtrCpuLevel)level);
        if (table.bvh_closest_hit != last) {
            last = table.bvh_closest_hit;
            methods[n++] = (Method){ .name = ptr_cpu_level_name((PtrCpuLevel)level),
                                     .kind = PTR_ONE_RAY, .traversal = last };
        }
    }
    return n;
}

/* Every method (or the one named only), best of runs, against Embree's
 * best, and how often Embree's answers differ from the C reference's. */
static void compare(const PtrAccel *accel, PtrBvhClosestHitFn reference, const char *only,
                    int runs)
{
    /* The ladder's traversals, the table as asked, and Embree's four ways. */
    Method methods[PTR_CPU_LEVEL_COUNT + 5];
    int n = ladder_methods(methods);
    methods[n++] = (Method){ .name = "as asked", .kind = PTR_AS_ASKED };
    methods[n++] = (Method){ .name = "embree point 1", .kind = EMBREE_POINT_1 };
    methods[n++] = (Method){ .name = "embree point 16", .kind = EMBREE_POINT_16 };
    methods[n++] = (Method){ .name = "embree user 1", .kind = EMBREE_USER_1 };
    methods[n++] = (Method){ .name = "embree user 16", .kind = EMBREE_USER_16 };

    /* Embree's trees only where an Embree method is timed: at 10^8 spheres
     * they take gigabytes. */
    int embree_timed = 0;
    for (int k = 0; k < n; k++)
        embree_timed |= methods[k].kind >= EMBREE_POINT_1 &&
                        (!only || !strcmp(only, methods[k].name));
    const PtrSpheres *s = accel->spheres;
    RTCDevice device = embree_timed ? rtcNewDevice("threads=1") : NULL;
    RTCScene points = embree_timed ? embree_scene(device, s, s->count, 0) : NULL;
    RTCScene user = embree_timed ? embree_scene(device, s, s->count, 1) : NULL;
    float *embree_t = embree_timed ? malloc(recorded_count * sizeof *embree_t) : NULL;
    if (embree_timed && !embree_t) {
        fprintf(stderr, "query: out of memory\n");
        exit(6);
    }
    for (int run = 0; run < runs; run++) {
        for (int k = 0; k < n; k++) {
            Method *m = &methods[k];
            if (only && strcmp(only, m->name))
                continue;
            switch (m->kind) {
            case PTR_ONE_RAY: time_ptr(m, accel, m->traversal); break;
            case PTR_AS_ASKED: time_ptr_as_asked(m, accel, &recorded_table); break;
            case EMBREE_POINT_1: time_embree1(m, points, NULL); break;
            case EMBREE_POINT_16: time_embree16(m, points); break;
            case EMBREE_USER_1: time_embree1(m, user, run == 0 ? embree_t : NULL); break;
            case EMBREE_USER_16: time_embree16(m, user); break;
            }
        }
    }

    size_t disagree = 0;
    for (size_t i = 0; !only && i < recorded_count; i++) {
        PtrHit hit;
        const int found = reference(&recorded[i], &accel->bvh, accel->spheres, &hit);
        if (found != !isnan(embree_t[i]) ||
            (found && fabsf(hit.t - embree_t[i]) > 1e-4f * hit.t))
            disagree++;
    }
    const double hz = tsc_hz();
    double embree_best = INFINITY;
    for (int k = 0; k < n; k++)
        if (methods[k].kind >= EMBREE_POINT_1 && methods[k].seconds > 0)
            embree_best = fmin(embree_best, methods[k].seconds);
    printf("%-16s %9s %9s %11s %13s\n", "method", "Mrays/s", "ns/ray", "cycles/ray",
           "Embree best /");
    for (int k = 0; k < n; k++) {
        const Method *m = &methods[k];
        if (m->seconds == 0)
            continue;
        printf("%-16s %9.2f %9.1f %11.0f", m->name, (double)recorded_count / m->seconds * 1e-6,
               m->seconds / (double)recorded_count * 1e9, m->seconds * hz / (double)recorded_count);
        if (isinf(embree_best)) /* Embree not timed */
            printf("%13s\n", "-");
        else
            printf("%12.2fx\n", embree_best / m->seconds);
    }
    if (!only)
        printf("Embree's tree (user geometry) and ptr's disagree on %zu of %zu rays (hit or t "
               "to 1e-4)\n", disagree, recorded_count);
    if (embree_timed) {
        rtcReleaseScene(points);
        rtcReleaseScene(user);
        rtcReleaseDevice(device);
    }
    free(embree_t);
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: query SCENE SPP [RUNS [METHOD]]\n");
        return 2;
    }
    const uint32_t spp = (uint32_t)atoi(argv[2]);
    const int runs = argc > 3 ? atoi(argv[3]) : 3;
    const char *only = argc > 4 ? argv[4] : NULL;
    if (runs < 1) {
        fprintf(stderr, "query: RUNS must be at least 1\n");
        return 2;
    }
    PtrScene scene;
    PtrStrings warnings = { 0 };
    PtrError err = { 0 };
    if (ptr_import_scene(argv[1], &(PtrImportOptions){ 0 }, &scene, &warnings, &err) != PTR_OK) {
        fprintf(stderr, "query: %s\n", err.message);
        return 1;
    }
    if (scene.huge.count) {
        fprintf(stderr, "query: %s has spheres ptr keeps in double; not a tree-only query\n",
                argv[1]);
        return 1;
    }
    PtrIsectTable c;
    ptr_isect_init_level(&c, PTR_CPU_NONE);
    PtrAccel accel;
    recorded = malloc(RAYS_MAX * sizeof *recorded);
    packet_start = malloc(RAYS_MAX);
    if (!recorded || !packet_start || ptr_accel_init(&accel, PTR_ACCEL_BVH, &c, 0, &scene, 0, NULL) != PTR_OK) {
        fprintf(stderr, "query: out of memory\n");
        return 6;
    }

    /* Record with the table of this CPU, as a render would trace. */
    ptr_isect_init(&recorded_table, PTR_KERNEL_AUTO, ptr_cpu_level(), SIZE_MAX, NULL);
    accel.isect = recorded_table;
    accel.isect.bvh_closest_hit = record_ray;
    accel.isect.bvh_closest_hit_packet = record_packet;
    PtrRenderSettings settings = { .width = scene.width ? scene.width : 400,
                                   .height = scene.height ? scene.height : 225,
                                   .samples = spp, .seed = 1, .max_depth = 50, .threads = 1 };
    float *rgb = malloc((size_t)settings.width * (size_t)settings.height * 3 * sizeof *rgb);
    if (!rgb || ptr_render(&scene, &accel, &settings, rgb, NULL, &err) != PTR_OK) {
        fprintf(stderr, "query: the recording render failed: %s\n", err.message);
        return 1;
    }
    printf("%s: %zu spheres, %dx%d, %u spp, %s integrator: %zu rays recorded%s\n", argv[1],
           accel.spheres->count, settings.width, settings.height, spp,
           ptr_integrator_name(ptr_render_integrator(&settings)), recorded_count,
           recorded_count == RAYS_MAX ? " (the first ones: the buffer is full)" : "");

    if (only && !strcmp(only, "warmed")) {
        Method ladder[PTR_CPU_LEVEL_COUNT];
        const Method *own = &ladder[ladder_methods(ladder) - 1];
        printf("%s traversal:\n", own->name);
        print_warmed(&accel, c.bvh_closest_hit, own->traversal, runs, tsc_hz());
    } else {
        compare(&accel, c.bvh_closest_hit, only, runs);
    }
    free(rgb);
    free(recorded);
    free(packet_start);
    ptr_accel_free(&accel);
    ptr_scene_free(&scene);
    ptr_strings_free(&warnings);
    return 0;
}
