/* Checks every assembly kernel the CPU can run against the C reference,
 * bit for bit: the intersectors on random and adversarial rays and sphere
 * sets, the denoiser's convolutions on random and adversarial layers; with
 * --bench, times the intersectors.
 *
 *   checkasm [--rays N] [--seed S]     check (default 1000000 rays per level)
 *   checkasm --bench                   nanoseconds per ray at 4..512 spheres,
 *                                      and of the tree at 10^3..10^6
 *
 * This file is the harness (checkasm.h): the checks of each field of the
 * kernel table are in the file named after it. */
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "checkasm.h"

#include <cpuid.h>
/* XGETBV with ECX = 1 (XINUSE) exists when CPUID.(0xD, 1):EAX bit 2 is set. */
uint32_t xinuse_supported(void)
{
    unsigned a, b, c, d;
    if (ptr_cpu_detected() < PTR_CPU_AVX2 || __get_cpuid_max(0, NULL) < 0xd)
        return 0;
    __cpuid_count(0xd, 1, a, b, c, d);
    return (a >> 2) & 1;
}

float uniform(PtrRng *rng, float lo, float hi)
{
    return lo + (hi - lo) * ptr_rng_float(rng);
}

/* 10^u for u uniform in [lo, hi]: every decade equally likely. */
static float log_uniform(PtrRng *rng, float lo, float hi)
{
    return powf(10.0f, uniform(rng, lo, hi));
}

PtrVec3 random_unit(PtrRng *rng)
{
    float z = uniform(rng, -1, 1), phi = uniform(rng, 0, 2 * PTR_PI);
    float r = sqrtf(fmaxf(0, 1 - z * z));
    return v3_normalize(v3(r * cosf(phi), r * sinf(phi), z));
}

void set_ray(Case *c, PtrVec3 o, PtrVec3 d, PtrRng *rng)
{
    d = v3_normalize(d);
    float tmin = ptr_rng_float(rng) < 0.7f ? 0.0f : log_uniform(rng, -8, 1);
    float tmax = ptr_rng_float(rng) < 0.7f ? INFINITY : tmin + log_uniform(rng, -3, 7);
    c->ray = (PtrRay){ { o.x, o.y, o.z }, tmin, { d.x, d.y, d.z }, tmax };
}

/* A cluster of spheres at a random scale and distance from the origin, and a
 * ray from inside it, aimed at a sphere or anywhere. */
static void random_case(Case *c, PtrRng *rng, int extreme)
{
    float scale = extreme ? log_uniform(rng, -12, 12) : log_uniform(rng, -6, 6);
    float offset = extreme ? log_uniform(rng, -3, 15) : log_uniform(rng, -3, 7);
    PtrVec3 base = v3_scale(random_unit(rng), offset);
    size_t n = ptr_rng_float(rng) < 0.9f ? (size_t)(ptr_rng_float(rng) * 80)
                                         : 80 + (size_t)(ptr_rng_float(rng) * 600);
    for (size_t i = 0; i < n; i++) {
        PtrVec3 p = v3_add(base, v3_scale(random_unit(rng), scale * ptr_rng_float(rng) * 4));
        float r = scale * (extreme ? log_uniform(rng, -20, 1) : log_uniform(rng, -3, 0));
        ptr_scene_add_sphere(&c->scene, p, r, 0, NULL);
    }
    PtrVec3 o = v3_add(base, v3_scale(random_unit(rng), scale * ptr_rng_float(rng) * 6));
    PtrVec3 d = random_unit(rng);
    if (n && ptr_rng_float(rng) < 0.7f) {
        size_t k = (size_t)(ptr_rng_float(rng) * n) % n;
        PtrVec3 target = v3_add(ptr_sphere_centre(&c->scene.spheres, k),
                                v3_scale(random_unit(rng), c->scene.spheres.radius[k] *
                                                               ptr_rng_float(rng) * 1.2f));
        if (ptr_rng_float(rng) < 0.2f)
            o = ptr_sphere_centre(&c->scene.spheres, k); /* start inside */
        PtrVec3 dir = v3_sub(target, o);
        if (v3_max_abs(dir) > 0)
            d = dir;
    }
    set_ray(c, o, d, rng);
}

/* Rays that touch a sphere exactly: with these values every step is exact,
 * so the discriminant is exactly 0 (and, one ulp away, just below or above). */
static void tangent_case(Case *c, PtrRng *rng)
{
    float r = (float)(1 + (int)(ptr_rng_float(rng) * 64)) / 8.0f;
    float d = (float)(1 + (int)(ptr_rng_float(rng) * 64));
    float nudge = ptr_rng_float(rng) < 0.5f ? 1.0f : ptr_rng_float(rng) < 0.5f ? 1.0f - 0x1p-23f
                                                                                : 1.0f + 0x1p-23f;
    for (int i = 0; i < 5; i++)
        ptr_scene_add_sphere(&c->scene, v3(r * nudge, 0, -d - 3.0f * (float)i), r, 0, NULL);
    set_ray(c, v3(0, 0, 0), v3(0, 0, -1), rng);
    c->ray.tmin = 0.0f;
    c->ray.tmax = INFINITY;
}

/* The same sphere at several indices, within and across SIMD steps: the
 * lowest index must win. */
static void tie_case(Case *c, PtrRng *rng)
{
    size_t n = 2 + (size_t)(ptr_rng_float(rng) * 60);
    PtrVec3 centre = v3(uniform(rng, -1, 1), uniform(rng, -1, 1), -10);
    for (size_t i = 0; i < n; i++) {
        int copy = ptr_rng_float(rng) < 0.4f;
        PtrVec3 p = copy ? centre : v3(uniform(rng, -5, 5), uniform(rng, -5, 5), uniform(rng, -30, -11));
        ptr_scene_add_sphere(&c->scene, p, copy ? 1.0f : 0.5f, 0, NULL);
    }
    set_ray(c, v3(0, 0, 0), v3_add(centre, v3(uniform(rng, -.5f, .5f), uniform(rng, -.5f, .5f), 0)),
            rng);
    c->ray.tmin = 0.0f;
    c->ray.tmax = INFINITY;
}

static void make_case(Case *c, PtrRng *rng)
{
    ptr_scene_init(&c->scene);
    float kind = ptr_rng_float(rng);
    if (kind < 0.6f)
        random_case(c, rng, 0);
    else if (kind < 0.75f)
        random_case(c, rng, 1);
    else if (kind < 0.88f)
        tangent_case(c, rng);
    else
        tie_case(c, rng);
    /* Test all spheres, or only the first few (the rest must be ignored). */
    size_t n = c->scene.spheres.count;
    c->count = ptr_rng_float(rng) < 0.8f ? n : (size_t)(ptr_rng_float(rng) * (float)(n + 1)) % (n + 1);
}

void print_status(const CheckedCallStatus *status)
{
    printf("%s%s%s\n", status->failures & 1 ? "; a callee-saved register was clobbered" : "",
           status->failures & 2 ? "; returned with dirty upper YMM state (no vzeroupper)" : "",
           status->check_xinuse ? "" : " (vzeroupper not checked: no XGETBV(1))");
}

/* One kernel's line of the result; whether it passed. */
static int report(const char *kind, const char *name, uint64_t rays, uint64_t hits,
                  uint64_t mismatches, const CheckedCallStatus *status)
{
    printf("%s%-7s %" PRIu64 " rays (%" PRIu64 " hits): %" PRIu64 " differ from c", kind, name,
           rays, hits, mismatches);
    print_status(status);
    return !mismatches && !status->failures;
}

static int check(uint64_t rays, uint64_t seed)
{
    PtrIsectTable tables[PTR_CPU_LEVEL_COUNT];
    Tally one = { 0 }, packets = { 0 };
    PtrCpuLevel top = ptr_cpu_level();
    int levels = 0;
    for (int l = PTR_CPU_SSE41; l <= (int)top; l++) {
        ptr_isect_init_level(&tables[l], (PtrCpuLevel)l);
        one.status[l].check_xinuse = packets.status[l].check_xinuse = xinuse_supported();
        levels += tables[l].closest_hit != ptr_closest_hit_c;
    }
    if (!levels) {
        /* ctest's skip code (tests/CMakeLists.txt): a run that checked
         * nothing must not pass. */
        printf("skipped: no assembly intersector at CPU level %s in this build\n",
               ptr_cpu_level_name(top));
        return 77;
    }

    /* One stream of cases for both brute-force fields: every eighth case
     * also draws a packet around its ray. */
    PtrRng rng = ptr_rng_for_sample(seed, 0, 0);
    for (uint64_t i = 0; i < rays; i++) {
        Case c;
        make_case(&c, &rng);
        check_closest_hit(tables, top, &c, i, &one);
        if (i % PTR_PACKET_LANES == 0)
            check_closest_hit_packet(tables, top, &c, &rng, &packets);
        ptr_scene_free(&c.scene);
    }

    int passed = 0, failed = 0;
    for (int l = PTR_CPU_SSE41; l <= (int)top; l++)
        if (tables[l].closest_hit != ptr_closest_hit_c)
            report("", tables[l].name, rays, one.hits, one.mismatches[l], &one.status[l])
                ? passed++ : failed++;
    for (int l = PTR_CPU_SSE41; l <= (int)top; l++)
        if (tables[l].closest_hit_packet != ptr_closest_hit_packet_c)
            report("packet ", tables[l].name, rays, packets.hits, packets.mismatches[l],
                   &packets.status[l]) ? passed++ : failed++;
    failed += check_bvh_closest_hit(seed, &passed);
    failed += check_conv3x3(seed, &passed);
    failed += check_bvh_bin(seed, &passed);
    printf("%d passed, %d failed\n", passed, failed);
    return failed ? 1 : 0;
}

double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int main(int argc, char **argv)
{
    uint64_t rays = 1000000, seed = 1;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--bench")) {
            bench_closest_hit();
            bench_bvh_closest_hit();
            return 0;
        }
        if (!strcmp(argv[i], "--rays") && i + 1 < argc)
            rays = strtoull(argv[++i], NULL, 10);
        else if (!strcmp(argv[i], "--seed") && i + 1 < argc)
            seed = strtoull(argv[++i], NULL, 10);
        else {
            fprintf(stderr, "usage: checkasm [--rays N] [--seed S] | --bench\n");
            return 2;
        }
    }
    printf("checkasm: CPU level %s, seed %" PRIu64 "\n", ptr_cpu_level_name(ptr_cpu_level()), seed);
    return check(rays, seed);
}
