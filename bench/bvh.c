/* Scaling with the scene: cloud scenes of 10^3 to 10^6 spheres built in
 * memory (the distribution of ../shared/bench-scenes/gen_cloud.py: a ground
 * of radius 1000 under spheres filling a 20x6x20 box at a volume fraction of
 * 8%, 80% diffuse, 15% metal, 5% glass, the same camera), rendered with
 * brute force and with the tree, C and the fastest assembly the table has.
 *
 *   bvh [OUT.csv] [MAX_SPHERES] [WIDTH HEIGHT SPP]
 *   bvh --crossover [WIDTH HEIGHT SPP]
 *
 * The second form renders clouds of 3 to 1023 spheres (and the ground), to
 * find where the tree starts to beat brute force (PTR_ACCEL_CROSSOVER).
 *
 * Prints, per sphere count: the tree's build seconds, the bytes per sphere
 * of the tree plus the sphere arrays, the render's Mrays/s (camera and
 * scattered rays) for each method, and the seconds of the tree's render with
 * the table's traversal (build + that: the figure to set against Embree's); writes the same as CSV rows if asked.
 * Brute force is skipped where one render would take more than about a
 * minute (from 10^5 spheres on), and shown as "-". */
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "accel/accel.h"
#include "base/cpu.h"
#include "render/render.h"
#include "sampling/rng.h"

enum { BRUTE_MAX_SPHERES = 20000 };

static float uniform(PtrRng *rng, float lo, float hi)
{
    return lo + (hi - lo) * ptr_rng_float(rng);
}

/* The cloud of gen_cloud.py with n spheres, coordinates relative to the
 * camera as the importers store them. Returns 0 if out of memory. */
static int make_cloud(PtrScene *scene, size_t n, uint64_t seed)
{
    const PtrVec3 eye = v3(0, 9, 26);
    ptr_scene_init(scene);
    for (int a = 0; a < 3; a++)
        scene->origin[a] = (&eye.x)[a];
    scene->camera = (PtrCamera){ .lookfrom = v3(0, 0, 0), .lookat = v3_sub(v3(0, 2, 0), eye),
                                 .up = v3(0, 1, 0), .vfov_deg = 40.0f, .aperture = 0.0f,
                                 .focus_distance = 26.0f, .aspect = 16.0f / 9.0f };
    PtrRng rng = ptr_rng_for_sample(seed, n, 0);
    const float box[3] = { 20.0f, 6.0f, 20.0f };
    float r = cbrtf(0.08f * box[0] * box[1] * box[2] / (float)n * 3.0f / (4.0f * PTR_PI));
    uint32_t ground;
    PtrMaterial m = { .kind = PTR_MATERIAL_DIFFUSE, .albedo = v3(0.5f, 0.5f, 0.5f) };
    int ok = ptr_scene_add_material(scene, &m, &ground, NULL) == PTR_OK &&
             ptr_scene_add_sphere(scene, v3_sub(v3(0, -1000, 0), eye), 1000.0f, ground, NULL) == PTR_OK;
    for (size_t i = 0; ok && i < n; i++) {
        PtrVec3 c = v3(uniform(&rng, -10, 10), uniform(&rng, r, box[1]), uniform(&rng, -10, 10));
        float kind = ptr_rng_float(&rng);
        if (kind < 0.8f)
            m = (PtrMaterial){ .kind = PTR_MATERIAL_DIFFUSE,
                               .albedo = v3(ptr_rng_float(&rng) * ptr_rng_float(&rng),
                                            ptr_rng_float(&rng) * ptr_rng_float(&rng),
                                            ptr_rng_float(&rng) * ptr_rng_float(&rng)) };
        else if (kind < 0.95f)
            m = (PtrMaterial){ .kind = PTR_MATERIAL_METAL,
                               .albedo = v3(uniform(&rng, 0.5f, 1), uniform(&rng, 0.5f, 1),
                                            uniform(&rng, 0.5f, 1)),
                               .fuzz = 0.1f * (float)(ptr_rng_next(&rng) % 6) };
        else
            m = (PtrMaterial){ .kind = PTR_MATERIAL_DIELECTRIC, .albedo = v3(1, 1, 1), .ior = 1.5f };
        uint32_t material;
        ok = ptr_scene_add_material(scene, &m, &material, NULL) == PTR_OK &&
             ptr_scene_add_sphere(scene, v3_sub(c, eye), r, material, NULL) == PTR_OK;
    }
    return ok;
}

typedef struct Setup {
    int width, height;
    uint32_t spp;
} Setup;

/* Mrays/s of one render (its seconds in *seconds), or NAN if it fails. */
static double mrays(const PtrScene *scene, const PtrAccel *accel, const Setup *setup,
                    double *seconds)
{
    PtrRenderSettings s = { .width = setup->width, .height = setup->height,
                            .samples = setup->spp, .seed = 1, .max_depth = 50 };
    float *rgb = malloc((size_t)s.width * (size_t)s.height * 3 * sizeof *rgb);
    PtrRenderStats stats;
    PtrError err = { 0 };
    int ok = rgb && ptr_render(scene, accel, &s, rgb, &stats, &err) == PTR_OK;
    free(rgb);
    *seconds = ok ? stats.seconds : NAN;
    return ok ? (double)stats.rays / stats.seconds * 1e-6 : NAN;
}

int main(int argc, char **argv)
{
    int crossover = argc > 1 && !strcmp(argv[1], "--crossover");
    FILE *csv = argc > 1 && !crossover ? fopen(argv[1], "w") : NULL;
    if (argc > 1 && !crossover && !csv) {
        fprintf(stderr, "bvh: cannot write %s\n", argv[1]);
        return 1;
    }
    size_t max_spheres = crossover ? 1023 : argc > 2 ? strtoull(argv[2], NULL, 10) : 1000000;
    Setup setup = { 200, 113, 2 };
    if (argc > 5 || (crossover && argc > 4))
        setup = (Setup){ atoi(argv[argc - 3]), atoi(argv[argc - 2]), (uint32_t)atoi(argv[argc - 1]) };

    PtrIsectTable c, fastest;
    ptr_isect_init_level(&c, PTR_CPU_NONE);
    ptr_isect_init(&fastest, PTR_KERNEL_AUTO, ptr_cpu_level(), SIZE_MAX, NULL);
    printf("cloud scenes, %dx%d, %" PRIu32 " spp, %d threads; Mrays/s (camera and scattered rays)\n",
           setup.width, setup.height, setup.spp, ptr_usable_cpus());
    printf("%9s %9s %8s %5s %11s %11s %11s %11s %11s\n", "spheres", "build s", "bytes/sp", "depth",
           "brute c", "brute asm", "bvh c", "bvh asm", "bvh asm s");
    if (csv)
        fprintf(csv, "spheres,build_seconds,bytes_per_sphere,brute_c,brute_asm,bvh_c,bvh_asm,asm\n");
    for (size_t n = crossover ? 3 : 1000; n <= max_spheres; n = crossover ? 2 * n + 1 : 10 * n) {
        PtrScene scene;
        if (!make_cloud(&scene, n, 7)) {
            fprintf(stderr, "bvh: out of memory at %zu spheres\n", n);
            return 1;
        }
        double rate[4] = { NAN, NAN, NAN, NAN }, seconds[4] = { NAN, NAN, NAN, NAN };
        if (n <= BRUTE_MAX_SPHERES) {
            PtrAccel brute_c = ptr_accel_brute(&c, &scene);
            PtrAccel brute_asm = ptr_accel_brute(&fastest, &scene);
            rate[0] = mrays(&scene, &brute_c, &setup, &seconds[0]);
            rate[1] = mrays(&scene, &brute_asm, &setup, &seconds[1]);
        }
        PtrAccel tree;
        if (ptr_accel_init(&tree, PTR_ACCEL_BVH, &c, 0, &scene, 0, NULL) != PTR_OK) {
            fprintf(stderr, "bvh: out of memory building the tree over %zu spheres\n", n);
            return 1;
        }
        /* The renderer's arrays (centre, radius, material) and nodes, not
         * counting the room the arrays grew into. */
        const PtrSpheres *s = &scene.spheres;
        double bytes = (double)(s->count * (4 * sizeof(float) + s->material_size) +
                                tree.bvh.node_count * sizeof(PtrBvhNode)) / (double)s->count;
        rate[2] = mrays(&scene, &tree, &setup, &seconds[2]);
        tree.isect = fastest;
        rate[3] = mrays(&scene, &tree, &setup, &seconds[3]);
        char cells[4][16];
        for (int k = 0; k < 4; k++)
            snprintf(cells[k], sizeof cells[k], isnan(rate[k]) ? "-" : "%.3f", rate[k]);
        printf("%9zu %9.4f %8.1f %5d %11s %11s %11s %11s %11.3f\n", scene.spheres.count,
               tree.build_seconds, bytes, tree.bvh.depth, cells[0], cells[1], cells[2], cells[3],
               seconds[3]);
        fflush(stdout);
        if (csv)
            fprintf(csv, "%zu,%.6f,%.2f,%.6g,%.6g,%.6g,%.6g,%s\n", scene.spheres.count,
                    tree.build_seconds, bytes, rate[0], rate[1], rate[2], rate[3], fastest.name);
        ptr_accel_free(&tree);
        ptr_scene_free(&scene);
    }
    if (csv)
        fclose(csv);
    return 0;
}
