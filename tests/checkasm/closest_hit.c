/* The table's closest_hit, one ray against a run of spheres: every level's
 * kernel against ptr_closest_hit_c, bit for bit (return value, t and
 * sphere), and their times. */
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "checkasm.h"

static void print_hit(const char *who, int ret, const PtrHit *h)
{
    fprintf(stderr, "    %-7s returned %d, t = %.9g (%a), sphere = %" PRIu32 "\n", who, ret, h->t,
            h->t, h->sphere);
}

void check_closest_hit(const PtrIsectTable *tables, PtrCpuLevel top, const Case *c,
                       uint64_t ray_index, Tally *tally)
{
    PtrHit ref;
    memset(&ref, 0xaa, sizeof ref);
    int ref_ret = ptr_closest_hit_c(&c->ray, &c->scene.spheres, c->count, &ref);
    tally->hits += ref_ret;
    for (int l = PTR_CPU_SSE41; l <= (int)top; l++) {
        if (tables[l].closest_hit == ptr_closest_hit_c)
            continue;
        PtrHit got;
        memset(&got, 0x55, sizeof got); /* a different sentinel: unwritten shows */
        int ret = ptr_checked_call(tables[l].closest_hit, &c->ray, &c->scene.spheres, c->count,
                                   &got, &tally->status[l]);
        if (ret == ref_ret && !memcmp(&got, &ref, sizeof got))
            continue;
        if (tally->mismatches[l]++ < 5) {
            fprintf(stderr, "%s differs from c on ray %" PRIu64 " (count %zu, tmin %a, tmax %a):\n",
                    tables[l].name, ray_index, c->count, c->ray.tmin, c->ray.tmax);
            print_hit("c", ref_ret, &ref);
            print_hit(tables[l].name, ret, &got);
        }
    }
}

/* Nanoseconds per closest-hit query: random rays from outside a box of
 * spheres into it, as in a scene where most spheres are missed. */
static double time_kernel(PtrClosestHitFn fn, const PtrScene *scene, const PtrRay *rays,
                          size_t ray_count)
{
    double best = INFINITY;
    volatile uint32_t sink = 0;
    for (int rep = 0; rep < 5; rep++) {
        size_t queries = 0;
        double start = now(), elapsed;
        do {
            for (size_t i = 0; i < ray_count; i++) {
                PtrHit hit;
                fn(&rays[i], &scene->spheres, scene->spheres.count, &hit);
                sink += hit.sphere;
            }
            queries += ray_count;
            elapsed = now() - start;
        } while (elapsed < 0.05);
        best = fmin(best, elapsed / (double)queries * 1e9);
    }
    (void)sink;
    return best;
}

void bench_closest_hit(void)
{
    enum { RAYS = 1024 };
    static const size_t sizes[] = { 4, 16, 64, 512 };
    PtrRng rng = ptr_rng_for_sample(7, 0, 0);
    PtrRay rays[RAYS];
    PtrCpuLevel top = ptr_cpu_level();

    printf("%-8s %10s", "spheres", "c ns/ray");
    for (int l = PTR_CPU_SSE41; l <= (int)top; l++)
        printf("  %7s ns/ray (x c)", ptr_cpu_level_name((PtrCpuLevel)l));
    printf("\n");
    for (size_t s = 0; s < sizeof sizes / sizeof sizes[0]; s++) {
        PtrScene scene;
        ptr_scene_init(&scene);
        for (size_t i = 0; i < sizes[s]; i++)
            ptr_scene_add_sphere(&scene, v3(uniform(&rng, -10, 10), uniform(&rng, -1, 1),
                                            uniform(&rng, -10, 10)),
                                 uniform(&rng, 0.2f, 0.5f), 0, NULL);
        for (int i = 0; i < RAYS; i++) {
            PtrVec3 o = v3(uniform(&rng, -15, 15), uniform(&rng, 0, 3), 15);
            PtrVec3 d = v3_normalize(v3_sub(v3(uniform(&rng, -10, 10), 0, uniform(&rng, -10, 10)), o));
            rays[i] = (PtrRay){ { o.x, o.y, o.z }, 0, { d.x, d.y, d.z }, INFINITY };
        }
        double c_ns = time_kernel(ptr_closest_hit_c, &scene, rays, RAYS);
        printf("%-8zu %10.1f", sizes[s], c_ns);
        for (int l = PTR_CPU_SSE41; l <= (int)top; l++) {
            PtrIsectTable t;
            ptr_isect_init_level(&t, (PtrCpuLevel)l);
            double ns = time_kernel(t.closest_hit, &scene, rays, RAYS);
            printf("  %14.1f (%4.1fx)", ns, c_ns / ns);
        }
        printf("\n");
        ptr_scene_free(&scene);
    }
}
