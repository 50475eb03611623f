/* Sphere sets that are hard for a tree, and rays to shoot at them: for the
 * tree's tests and the assembly checker. Every set is a function of its
 * kind, size and seed, so a test can build it twice (one copy for the tree,
 * which reorders it, one in file order for brute force). */
#ifndef PTR_BVH_SCENES_H
#define PTR_BVH_SCENES_H

#include <math.h>
#include <stdint.h>

#include "accel/ray.h"
#include "sampling/rng.h"
#include "scene/scene.h"

typedef enum BvhSceneKind {
    BVH_SCENE_RANDOM,        /* uniform in a box, radii 0.05 to 0.5 */
    BVH_SCENE_DUPLICATES,    /* every sphere three times, exactly */
    BVH_SCENE_CONCENTRIC,    /* one centre, radii 0.1 to 20 */
    BVH_SCENE_COLLINEAR,     /* centres on one line, overlapping */
    BVH_SCENE_SAME_CENTRE,   /* one centre, one radius */
    BVH_SCENE_SHEET,         /* a flat grid of touching spheres */
    BVH_SCENE_GROUND,        /* a radius 1000 ground under tiny spheres */
    BVH_SCENE_BIG_GROUND,    /* a radius 1e5 ground under tiny spheres */
    BVH_SCENE_RADII,         /* radii from 1e-4 to 1e3 */
    BVH_SCENE_FAR,           /* 1e6 to 1e7 from the origin */
    BVH_SCENE_CLUSTERS,      /* overlapping dense clusters */
    BVH_SCENE_KIND_COUNT,
} BvhSceneKind;

static const char *const bvh_scene_names[BVH_SCENE_KIND_COUNT] = {
    "random", "duplicates", "concentric", "collinear", "same centre", "sheet",
    "ground", "big ground", "radii", "far", "clusters",
};

static inline float bvh_uniform(PtrRng *rng, float lo, float hi)
{
    return lo + (hi - lo) * ptr_rng_float(rng);
}

/* Fills scene (initialised, empty, with one material) with about n spheres.
 * Returns 0 if out of memory. */
static inline int bvh_scene_make(PtrScene *scene, BvhSceneKind kind, int n, uint64_t seed)
{
    PtrRng rng = ptr_rng_for_sample(seed, (uint64_t)kind, 0);
    int ok = 1;
#define ADD(x, y, z, r) (ok &= ptr_scene_add_sphere(scene, v3((x), (y), (z)), (r), 0, NULL) == PTR_OK)
    switch (kind) {
    case BVH_SCENE_RANDOM:
        for (int i = 0; i < n; i++)
            ADD(bvh_uniform(&rng, -10, 10), bvh_uniform(&rng, -10, 10),
                bvh_uniform(&rng, -10, 10), bvh_uniform(&rng, 0.05f, 0.5f));
        break;
    case BVH_SCENE_DUPLICATES:
        for (int i = 0; i < n / 3; i++) {
            float x = bvh_uniform(&rng, -5, 5), y = bvh_uniform(&rng, -5, 5);
            float z = bvh_uniform(&rng, -5, 5), r = bvh_uniform(&rng, 0.1f, 1.0f);
            for (int k = 0; k < 3; k++)
                ADD(x, y, z, r);
        }
        break;
    case BVH_SCENE_CONCENTRIC:
        for (int i = 0; i < n; i++)
            ADD(1.0f, 2.0f, -3.0f, 0.1f + 19.9f * ptr_rng_float(&rng));
        break;
    case BVH_SCENE_COLLINEAR:
        for (int i = 0; i < n; i++) {
            float s = bvh_uniform(&rng, -20, 20);
            ADD(s, 0.5f * s, -s, bvh_uniform(&rng, 0.1f, 2.0f));
        }
        break;
    case BVH_SCENE_SAME_CENTRE:
        for (int i = 0; i < n; i++)
            ADD(0.5f, 0.25f, -2.0f, 1.5f);
        break;
    case BVH_SCENE_SHEET: {
        int side = (int)sqrt((double)n);
        for (int i = 0; i < side; i++)
            for (int j = 0; j < side; j++)
                ADD((float)i * 0.8f - 20.0f, -1.0f, (float)j * 0.8f - 20.0f, 0.4f);
        break;
    }
    case BVH_SCENE_GROUND:
    case BVH_SCENE_BIG_GROUND: {
        float g = kind == BVH_SCENE_GROUND ? 1000.0f : 1e5f;
        ADD(0.0f, -g, 0.0f, g);
        for (int i = 1; i < n; i++)
            ADD(bvh_uniform(&rng, -10, 10), bvh_uniform(&rng, 0, 3), bvh_uniform(&rng, -10, 10),
                bvh_uniform(&rng, 0.01f, 0.2f));
        break;
    }
    case BVH_SCENE_RADII:
        for (int i = 0; i < n; i++)
            ADD(bvh_uniform(&rng, -50, 50), bvh_uniform(&rng, -50, 50), bvh_uniform(&rng, -50, 50),
                powf(10.0f, bvh_uniform(&rng, -4, 3)));
        break;
    case BVH_SCENE_FAR:
        for (int i = 0; i < n; i++) {
            float d = powf(10.0f, bvh_uniform(&rng, 6, 7));
            ADD(d + bvh_uniform(&rng, -1e4f, 1e4f), bvh_uniform(&rng, -1e4f, 1e4f),
                -d + bvh_uniform(&rng, -1e4f, 1e4f), powf(10.0f, bvh_uniform(&rng, 0, 3)));
        }
        break;
    case BVH_SCENE_CLUSTERS:
        for (int i = 0; i < n; i++) {
            int c = i % 5;
            ADD((float)c * 2.0f + bvh_uniform(&rng, -1, 1), bvh_uniform(&rng, -1, 1),
                (float)c + bvh_uniform(&rng, -1, 1), bvh_uniform(&rng, 0.2f, 1.5f));
        }
        break;
    case BVH_SCENE_KIND_COUNT:
        break;
    }
#undef ADD
    return ok;
}

/* A ray at the spheres of s (in file order): from the origin, from inside
 * the scene, from a sphere's surface, aimed at a sphere, or grazing one at
 * exactly its radius. */
static inline PtrRay bvh_scene_ray(const PtrSpheres *s, PtrRng *rng)
{
    size_t i = (size_t)(ptr_rng_next(rng) % s->count);
    PtrVec3 c = ptr_sphere_centre(s, i);
    float r = s->radius[i];
    PtrVec3 dir = v3_normalize(v3(bvh_uniform(rng, -1, 1), bvh_uniform(rng, -1, 1),
                                  bvh_uniform(rng, -1, 1)));
    PtrVec3 org = v3(0, 0, 0), target = c;
    switch (ptr_rng_next(rng) % 5) {
    case 0: /* from the origin, in any direction */
        target = v3_add(org, dir);
        break;
    case 1: { /* from near another sphere, at this one */
        size_t j = (size_t)(ptr_rng_next(rng) % s->count);
        org = v3_madd(ptr_sphere_centre(s, j), dir, s->radius[j] * bvh_uniform(rng, 0.5f, 2.0f));
        target = v3_madd(c, dir, r * bvh_uniform(rng, -1, 1));
        break;
    }
    case 2: /* from this sphere's surface, in any direction */
        org = v3_madd(c, dir, r * (1.0f + 0x1.0p-20f));
        target = v3_add(org, v3(bvh_uniform(rng, -1, 1), bvh_uniform(rng, -1, 1),
                                bvh_uniform(rng, -1, 1)));
        break;
    case 3: /* from the origin, at a point of the sphere */
        target = v3_madd(c, dir, r);
        break;
    default: { /* grazing: along a tangent, from the origin's side */
        PtrVec3 to = v3_normalize(v3_sub(c, org));
        PtrVec3 side = v3_normalize(v3_cross(to, dir));
        target = v3_madd(c, side, r);
        break;
    }
    }
    PtrVec3 d = v3_normalize(v3_sub(target, org));
    if (!(v3_length(d) > 0.5f))
        d = dir;
    return (PtrRay){ { org.x, org.y, org.z }, 0.0f, { d.x, d.y, d.z }, INFINITY };
}

#endif /* PTR_BVH_SCENES_H */
