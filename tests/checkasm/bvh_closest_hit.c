/* The table's bvh_closest_hit, the tree traversal: every assembly level's
 * against the C traversal (the same answer to the bit: return value, t and
 * sphere) and the C traversal against brute force over the same reordered
 * arrays (the same t and the same sphere), on the hard sets of
 * tests/support/bvh_scenes.h: duplicates, concentric, collinear, one centre,
 * a flat sheet, grounds of radius 1000 and 1e5 under tiny spheres, radii from
 * 1e-4 to 1e3, far from the origin, overlapping clusters, of 1 to 3000
 * spheres, with rays from the origin, from sphere surfaces, at spheres and
 * grazing them, and random tmin and tmax, or tmax at the nearest hit. */
#include <inttypes.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "bvh_scenes.h"
#include "checkasm.h"

enum { RAYS_PER_SCENE = 2000 };

static const int sizes[] = { 1, 2, 7, 8, 9, 40, 333, 3000 };

/* A ray of bvh_scene_ray with tmin and tmax of every kind the renderer uses
 * and a few it does not: among them tmax exactly the t of the nearest hit,
 * which must not count (a t equal to the best one's goes to the positions,
 * and before any hit there is no best position to win against). */
static PtrRay checked_ray(const PtrSpheres *s, PtrRng *rng)
{
    PtrRay ray = bvh_scene_ray(s, rng);
    PtrHit nearest;
    switch (ptr_rng_next(rng) % 5) {
    case 0: ray.tmin = 1e-3f; break;
    case 1: ray.tmax = bvh_uniform(rng, 0.01f, 30.0f); break;
    case 2: ray.tmin = bvh_uniform(rng, 0.0f, 5.0f); ray.tmax = ray.tmin + bvh_uniform(rng, 1e-3f, 20.0f); break;
    case 3:
        if (ptr_closest_hit_c(&ray, s, s->count, &nearest))
            ray.tmax = nearest.t;
        break;
    default: break;
    }
    return ray;
}

static void print_hit(const char *who, int ret, const PtrHit *h)
{
    fprintf(stderr, "    %-7s returned %d, t = %.9g (%a), sphere = %" PRIu32 "\n", who, ret, h->t,
            h->t, h->sphere);
}

int check_bvh_closest_hit(uint64_t seed, int *passed)
{
    PtrIsectTable tables[PTR_CPU_LEVEL_COUNT];
    CheckedCallStatus status[PTR_CPU_LEVEL_COUNT] = { { 0 } };
    uint64_t mismatches[PTR_CPU_LEVEL_COUNT] = { 0 }, rays = 0, hits = 0, brute_mismatches = 0;
    PtrCpuLevel top = ptr_cpu_level();
    Tally packet_tally = { 0 };
    uint64_t packets = 0;
    for (int l = PTR_CPU_SSE41; l <= (int)top; l++) {
        ptr_isect_init_level(&tables[l], (PtrCpuLevel)l);
        status[l].check_xinuse = packet_tally.status[l].check_xinuse = xinuse_supported();
    }
    for (int kind = 0; kind < BVH_SCENE_KIND_COUNT; kind++) {
        for (size_t z = 0; z < sizeof sizes / sizeof sizes[0]; z++) {
            PtrScene tree_scene;
            ptr_scene_init(&tree_scene);
            PtrBvh bvh;
            uint64_t scene_seed = seed * 1000 + z;
            if (!bvh_scene_make(&tree_scene, (BvhSceneKind)kind, sizes[z], scene_seed)) {
                fprintf(stderr, "check_bvh: out of memory\n");
                return 1;
            }
            if (tree_scene.spheres.count == 0) { /* duplicates of fewer than 3 */
                ptr_scene_free(&tree_scene);
                continue;
            }
            if (ptr_bvh_build(&bvh, &tree_scene.spheres, tree_scene.spheres.count, 0,
                              ptr_cpu_level(), NULL) != PTR_OK) {
                fprintf(stderr, "check_bvh: cannot build %s %d\n", bvh_scene_names[kind], sizes[z]);
                return 1;
            }
            const PtrSpheres *t = &tree_scene.spheres;
            PtrRng rng = ptr_rng_for_sample(scene_seed, (uint64_t)kind, 1);
            for (int r = 0; r < RAYS_PER_SCENE; r++, rays++) {
                const PtrRay ray = checked_ray(t, &rng);
                PtrHit ref, brute;
                memset(&ref, 0xaa, sizeof ref);
                int ref_ret = ptr_bvh_closest_hit_c(&ray, &bvh, t, &ref);
                int brute_ret = ptr_closest_hit_c(&ray, t, t->count, &brute);
                hits += ref_ret;
                if (ref_ret != brute_ret || ref.t != brute.t || ref.sphere != brute.sphere) {
                    if (brute_mismatches++ < 5) {
                        fprintf(stderr, "the C traversal differs from brute force (%s, %d spheres):\n",
                                bvh_scene_names[kind], sizes[z]);
                        print_hit("tree", ref_ret, &ref);
                        print_hit("brute", brute_ret, &brute);
                    }
                }
                for (int l = PTR_CPU_SSE41; l <= (int)top; l++) {
                    if (tables[l].bvh_closest_hit == ptr_bvh_closest_hit_c)
                        continue;
                    PtrHit got;
                    memset(&got, 0x55, sizeof got); /* a different sentinel: unwritten shows */
                    int ret = ptr_checked_call_bvh(tables[l].bvh_closest_hit, &ray, &bvh, t, &got,
                                                   &status[l]);
                    if (ret == ref_ret && !memcmp(&got, &ref, sizeof got))
                        continue;
                    if (mismatches[l]++ < 5) {
                        fprintf(stderr, "%s traversal differs from c (%s, %d spheres, tmin %a, tmax %a):\n",
                                tables[l].name, bvh_scene_names[kind], sizes[z], ray.tmin, ray.tmax);
                        print_hit("c", ref_ret, &ref);
                        print_hit(tables[l].name, ret, &got);
                    }
                }
            }
            packets += check_bvh_closest_hit_packet(tables, top, &bvh, t, checked_ray, &rng,
                                                    &packet_tally);
            ptr_bvh_free(&bvh);
            ptr_scene_free(&tree_scene);
        }
    }
    int failed = brute_mismatches != 0;
    printf("tree c  %" PRIu64 " rays (%" PRIu64 " hits): %" PRIu64 " differ from brute force\n", rays,
           hits, brute_mismatches);
    failed ? 0 : ++*passed;
    for (int l = PTR_CPU_SSE41; l <= (int)top; l++) {
        if (tables[l].bvh_closest_hit == ptr_bvh_closest_hit_c ||
            (l > PTR_CPU_SSE41 && tables[l].bvh_closest_hit == tables[l - 1].bvh_closest_hit))
            continue;
        int ok = !mismatches[l] && !status[l].failures;
        printf("tree %-7s %" PRIu64 " rays: %" PRIu64 " differ from c%s%s\n", tables[l].name, rays,
               mismatches[l],
               status[l].failures & 1 ? "; a callee-saved register was clobbered" : "",
               status[l].failures & 2 ? "; returned with dirty upper YMM state (no vzeroupper)" : "");
        ok ? ++*passed : ++failed;
    }
    report_bvh_closest_hit_packet(tables, top, packets, &packet_tally, passed, &failed);
    return failed;
}

static double time_traversal(PtrBvhClosestHitFn fn, const PtrBvh *bvh, const PtrSpheres *s,
                             const PtrRay *rays, size_t count)
{
    double best = INFINITY;
    volatile uint32_t sink = 0;
    for (int rep = 0; rep < 3; rep++) {
        double start = now();
        for (size_t i = 0; i < count; i++) {
            PtrHit hit;
            fn(&rays[i], bvh, s, &hit);
            sink += hit.sphere;
        }
        best = fmin(best, (now() - start) / (double)count * 1e9);
    }
    (void)sink;
    return best;
}

/* Clouds of spheres at a fixed volume fraction (as scripts/make_cloud.py
 * builds them, without the ground), rays from a camera in front of them. */
void bench_bvh_closest_hit(void)
{
    enum { RAYS = 20000 };
    static PtrRay rays[RAYS];
    /* The levels with a traversal of their own. */
    PtrBvhClosestHitFn fns[PTR_CPU_LEVEL_COUNT];
    const char *names[PTR_CPU_LEVEL_COUNT];
    int levels = 0;
    for (int l = PTR_CPU_SSE41; l <= (int)ptr_cpu_level(); l++) {
        PtrIsectTable t;
        ptr_isect_init_level(&t, (PtrCpuLevel)l);
        if (t.bvh_closest_hit != ptr_bvh_closest_hit_c &&
            (!levels || fns[levels - 1] != t.bvh_closest_hit)) {
            fns[levels] = t.bvh_closest_hit;
            names[levels++] = t.name;
        }
    }
    printf("\n%-8s %14s", "spheres", "tree c ns/ray");
    for (int l = 0; l < levels; l++)
        printf("  %7s ns/ray (x c)", names[l]);
    printf("\n");
    for (int n = 1000; n <= 1000000; n *= 10) {
        PtrScene scene;
        ptr_scene_init(&scene);
        PtrRng rng = ptr_rng_for_sample(3, (uint64_t)n, 0);
        const float r = cbrtf(0.08f * 2400.0f / (float)n * 3.0f / (4.0f * PTR_PI));
        for (int i = 0; i < n; i++)
            ptr_scene_add_sphere(&scene, v3(bvh_uniform(&rng, -10, 10), bvh_uniform(&rng, r, 6),
                                            bvh_uniform(&rng, -10, 10)), r, 0, NULL);
        PtrBvh bvh;
        if (ptr_bvh_build(&bvh, &scene.spheres, scene.spheres.count, 0, ptr_cpu_level(),
                          NULL) != PTR_OK)
            return;
        for (int i = 0; i < RAYS; i++) {
            PtrVec3 o = v3(0, 9, 26);
            PtrVec3 d = v3_normalize(v3_sub(v3(bvh_uniform(&rng, -12, 12), bvh_uniform(&rng, 0, 6),
                                               bvh_uniform(&rng, -10, 10)), o));
            rays[i] = (PtrRay){ { o.x, o.y, o.z }, 0, { d.x, d.y, d.z }, INFINITY };
        }
        double c_ns = time_traversal(ptr_bvh_closest_hit_c, &bvh, &scene.spheres, rays, RAYS);
        printf("%-8d %14.1f", n, c_ns);
        for (int l = 0; l < levels; l++) {
            double ns = time_traversal(fns[l], &bvh, &scene.spheres, rays, RAYS);
            printf("  %14.1f (%4.1fx)", ns, c_ns / ns);
        }
        printf("\n");
        ptr_bvh_free(&bvh);
        ptr_scene_free(&scene);
    }
}
