#include "accel/bvh_prims.h"

#include <math.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "base/threads.h"

/* The tree keeps the huge spheres among its own (scene.h's rule) out of its
 * boxes, with a limit of HUGE_RATIO times the median radius: a ground of
 * radius 1000 under spheres of 0.2, or 1e5 under 1, would otherwise make
 * one box span the scene and every ray visit much of the tree. (Spheres the
 * builder chose, against another limit, are tested in double and never
 * reach the tree.) */
enum { HUGE_RATIO = 100 };

/* The k-th smallest of values[0 .. n - 1] (reorders values). */
static float select_kth(float *values, size_t n, size_t k)
{
    size_t lo = 0, hi = n - 1;
    while (lo < hi) {
        float a = values[lo], b = values[lo + (hi - lo) / 2], c = values[hi];
        float pivot = a < b ? (b < c ? b : a < c ? c : a) : (a < c ? a : b < c ? c : b);
        size_t i = lo, j = hi;
        while (i <= j) {
            while (values[i] < pivot)
                i++;
            while (values[j] > pivot)
                j--;
            if (i <= j) {
                float t = values[i];
                values[i] = values[j];
                values[j] = t;
                i++;
                if (j == 0)
                    break;
                j--;
            }
        }
        if (k <= j)
            hi = j;
        else if (k >= i)
            lo = i;
        else
            return values[k];
    }
    return values[k];
}

/* The limit above which a radius is huge for the tree; NaN if out of
 * memory. */
static float huge_radius(const PtrSpheres *s)
{
    float *radii = malloc(s->count * sizeof *radii);
    if (!radii)
        return NAN;
    memcpy(radii, s->radius, s->count * sizeof *radii);
    float median = select_kth(radii, s->count, s->count / 2);
    free(radii);
    return median * HUGE_RATIO;
}

BvhPrim bvh_prim_of(const PtrSpheres *s, size_t i)
{
    BvhPrim p = { .centre = { s->cx[i], s->cy[i], s->cz[i] }, .radius = s->radius[i],
                  .id = ptr_sphere_id(s, i), .material = ptr_sphere_material(s, i) };
#define COPY_IN(name, type, per_sphere, none)                                              \
    if (s->name)                                                                           \
        memcpy(p.name, &s->name[(per_sphere) * i], sizeof p.name);
    PTR_SPHERE_ATTRIBUTES(COPY_IN)
#undef COPY_IN
    return p;
}

void bvh_prim_store(const BvhPrim *p, PtrSpheres *s, size_t i)
{
    s->cx[i] = p->centre[0];
    s->cy[i] = p->centre[1];
    s->cz[i] = p->centre[2];
    s->radius[i] = p->radius;
    ptr_sphere_set_material(s, i, p->material);
#define COPY_OUT(name, type, per_sphere, none)                                             \
    if (s->name)                                                                           \
        memcpy(&s->name[(per_sphere) * i], p->name, sizeof p->name);
    PTR_SPHERE_ATTRIBUTES(COPY_OUT)
#undef COPY_OUT
}

/* Spheres copied between two releases of the arrays' memory: 4 MB of each
 * float array. */
enum { RELEASE_STEP = 1 << 20 };

/* The copy of spheres into prims, in pieces on all threads: a piece's first
 * prim is its first sphere's index less the huge spheres before it, so the
 * pieces need nothing of each other. */
typedef struct PrimCopy {
    const PtrSpheres *spheres;
    BvhPrim *prims;
    const size_t *huge_index; /* ascending, then SIZE_MAX */
    /* The largest magnitude so far, as the bits of a float that is never
     * negative: such floats order as their bits do. */
    atomic_uint_least32_t magnitude;
} PrimCopy;

static void copy_prims(void *arg, size_t begin, size_t end)
{
    PrimCopy *c = arg;
    size_t k = 0;
    while (c->huge_index[k] < begin)
        k++;
    BvhPrim *out = c->prims + (begin - k);
    float magnitude = 0.0f;
    for (size_t i = begin; i < end; i++) {
        if (c->huge_index[k] == i) {
            k++;
            continue;
        }
        const float m = v3_max_abs(ptr_sphere_centre(c->spheres, i)) + c->spheres->radius[i];
        if (m > magnitude)
            magnitude = m;
        *out++ = bvh_prim_of(c->spheres, i);
    }
    uint32_t bits;
    memcpy(&bits, &magnitude, sizeof bits);
    uint_least32_t seen = atomic_load(&c->magnitude);
    while (bits > seen && !atomic_compare_exchange_weak(&c->magnitude, &seen, bits))
        ;
}

PtrResult ptr_bvh_prims(PtrSpheres *s, int threads, BvhPrim *huge, size_t *huge_count,
                        BvhPrim *prims, size_t *prim_count, float *magnitude_out, PtrError *err)
{
    *huge_count = *prim_count = 0;
    *magnitude_out = 0.0f;
    if (s->count == 0)
        return PTR_OK;
    PtrHugeChoice choice = { .limit = huge_radius(s) };
    if (isnan(choice.limit))
        return bvh_out_of_memory(err);
    for (size_t i = 0; i < s->count; i++)
        ptr_huge_offer(&choice, i, ptr_sphere_id(s, i), s->radius[i]);
    ptr_huge_file_order(&choice);
    /* By index, to skip them below. */
    size_t out[PTR_HUGE_MAX + 1];
    for (size_t k = 0; k < choice.count; k++) {
        huge[k] = bvh_prim_of(s, choice.sphere[k].index);
        size_t at = k;
        for (; at > 0 && out[at - 1] > choice.sphere[k].index; at--)
            out[at] = out[at - 1];
        out[at] = choice.sphere[k].index;
    }
    out[choice.count] = SIZE_MAX;
    PrimCopy copy = { .spheres = s, .prims = prims, .huge_index = out };
    atomic_init(&copy.magnitude, 0);
    for (size_t begin = 0; begin < s->count; begin += RELEASE_STEP) {
        const size_t end = s->count - begin > RELEASE_STEP ? begin + RELEASE_STEP : s->count;
        ptr_parallel_ranges(threads, begin, end, copy_prims, &copy);
        ptr_spheres_release(s, begin, end);
    }
    const uint32_t bits = (uint32_t)atomic_load(&copy.magnitude);
    memcpy(magnitude_out, &bits, sizeof bits);
    *huge_count = choice.count;
    *prim_count = s->count - choice.count;
    return PTR_OK;
}

void ptr_bvh_sort_leaf(BvhPrim *prims, size_t count)
{
    for (size_t i = 1; i < count; i++) {
        BvhPrim v = prims[i];
        size_t j = i;
        for (; j > 0 && prims[j - 1].id > v.id; j--)
            prims[j] = prims[j - 1];
        prims[j] = v;
    }
}
