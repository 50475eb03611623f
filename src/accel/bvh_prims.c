#include "accel/bvh_prims.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A sphere is kept out of the tree if its radius is more than UNBOUNDED_RATIO
 * times the median radius: a ground of radius 1000 under spheres of 0.2, or
 * 1e5 under 1, would otherwise make one box span the scene and every ray
 * visit much of the tree. At most BVH_UNBOUNDED_MAX of them (the largest), as
 * every ray tests them all. */
enum { UNBOUNDED_RATIO = 100 };


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

/* Whether sphere i comes before sphere j among those kept out: larger
 * first, then lower id. */
static int larger(const PtrSpheres *s, uint32_t i, uint32_t j)
{
    return s->radius[i] != s->radius[j] ? s->radius[i] > s->radius[j]
                                        : ptr_sphere_id(s, i) < ptr_sphere_id(s, j);
}

/* Offers sphere i to list[0 .. *n - 1], the largest so far, largest first:
 * it is kept if among the BVH_UNBOUNDED_MAX largest. */
static void offer_largest(uint32_t *list, size_t *n, uint32_t i, const PtrSpheres *s)
{
    size_t at = *n < BVH_UNBOUNDED_MAX ? (*n)++ : BVH_UNBOUNDED_MAX;
    for (; at > 0 && larger(s, i, list[at - 1]); at--)
        if (at < BVH_UNBOUNDED_MAX)
            list[at] = list[at - 1];
    if (at < BVH_UNBOUNDED_MAX)
        list[at] = i;
}

static void sort_by_id(uint32_t *list, size_t n, const PtrSpheres *s)
{
    for (size_t i = 1; i < n; i++) {
        uint32_t v = list[i];
        size_t j = i;
        for (; j > 0 && ptr_sphere_id(s, list[j - 1]) > ptr_sphere_id(s, v); j--)
            list[j] = list[j - 1];
        list[j] = v;
    }
}

/* The threshold above which a radius is kept out of the tree. */
static float unbounded_radius(const PtrSpheres *s)
{
    float *radii = malloc(s->count * sizeof *radii);
    if (!radii)
        return NAN;
    memcpy(radii, s->radius, s->count * sizeof *radii);
    float median = select_kth(radii, s->count, s->count / 2);
    free(radii);
    return median * UNBOUNDED_RATIO;
}

BvhPrim bvh_prim_of(const PtrSpheres *s, size_t i)
{
    BvhPrim p = { { s->cx[i], s->cy[i], s->cz[i] }, s->radius[i], ptr_sphere_id(s, i),
                  ptr_sphere_material(s, i),
                  { UINT16_MAX, UINT16_MAX, UINT16_MAX, UINT16_MAX } };
    if (s->color)
        memcpy(p.color, &s->color[4 * i], sizeof p.color);
    return p;
}

void bvh_prim_store(const BvhPrim *p, PtrSpheres *s, size_t i)
{
    s->cx[i] = p->centre[0];
    s->cy[i] = p->centre[1];
    s->cz[i] = p->centre[2];
    s->radius[i] = p->radius;
    ptr_sphere_set_material(s, i, p->material);
    if (s->color)
        memcpy(&s->color[4 * i], p->color, sizeof p->color);
}

/* Spheres copied between two releases of the arrays' memory: 4 MB of each
 * float array. */
enum { RELEASE_STEP = 1 << 20 };

PtrResult ptr_bvh_prims(PtrSpheres *s, BvhPrim *kept_out, size_t *kept_out_count, BvhPrim *prims,
                        size_t *prim_count, float *magnitude_out, PtrError *err)
{
    *kept_out_count = *prim_count = 0;
    *magnitude_out = 0.0f;
    if (s->count == 0)
        return PTR_OK;
    float limit = unbounded_radius(s);
    if (isnan(limit))
        return bvh_out_of_memory(err);
    uint32_t order[BVH_UNBOUNDED_MAX];
    size_t u = 0;
    for (size_t i = 0; i < s->count; i++)
        if (s->radius[i] > limit)
            offer_largest(order, &u, (uint32_t)i, s);
    /* By index, to skip them below; then by id, their order in the arrays. */
    uint32_t out[BVH_UNBOUNDED_MAX + 1];
    memcpy(out, order, u * sizeof *out);
    for (size_t i = 1; i < u; i++)
        for (size_t j = i; j > 0 && out[j - 1] > out[j]; j--) {
            uint32_t t = out[j];
            out[j] = out[j - 1];
            out[j - 1] = t;
        }
    out[u] = UINT32_MAX;
    sort_by_id(order, u, s);
    for (size_t k = 0; k < u; k++)
        kept_out[k] = bvh_prim_of(s, order[k]);
    float magnitude = 0.0f;
    size_t n = 0, k = 0;
    for (size_t begin = 0; begin < s->count; begin += RELEASE_STEP) {
        const size_t end = s->count - begin > RELEASE_STEP ? begin + RELEASE_STEP : s->count;
        for (size_t i = begin; i < end; i++) {
            if (out[k] == i) {
                k++;
                continue;
            }
            const float m = v3_max_abs(ptr_sphere_centre(s, i)) + s->radius[i];
            if (m > magnitude)
                magnitude = m;
            prims[n++] = bvh_prim_of(s, i);
        }
        ptr_spheres_release(s, begin, end);
    }
    *kept_out_count = u;
    *prim_count = n;
    *magnitude_out = magnitude;
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
