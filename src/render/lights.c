#include "render/lights.h"

#include <math.h>
#include <stdlib.h>

#include "base/trig.h"
#include "render/material.h"

/* Proportional to the flux a sphere emits: radiance (summed over channels)
 * times its area. */
static double sphere_power(const PtrScene *scene, uint32_t i)
{
    PtrVec3 e = scene->materials[ptr_sphere_material(&scene->spheres, i)].emission;
    double r = scene->spheres.radius[i];
    return ((double)e.x + e.y + e.z) * r * r;
}

static int is_emitter(const PtrScene *scene, uint32_t i)
{
    return v3_max_comp(scene->materials[ptr_sphere_material(&scene->spheres, i)].emission) > 0.0f &&
           scene->spheres.radius[i] > 0.0f;
}

/* Whether any material emits: where none does, no sphere is looked at (at
 * 10^8 spheres, a second's pass over 800 MB before the first ray). */
static int any_emissive_material(const PtrScene *scene)
{
    for (size_t m = 0; m < scene->material_count; m++)
        if (v3_max_comp(scene->materials[m].emission) > 0.0f)
            return 1;
    return 0;
}

PtrResult ptr_lights_init(PtrLights *l, const PtrScene *scene, PtrError *err)
{
    *l = (PtrLights){ 0 };
    if (!any_emissive_material(scene))
        return PTR_OK;
    size_t n = 0;
    for (size_t i = 0; i < scene->spheres.count; i++)
        n += is_emitter(scene, (uint32_t)i);
    if (n == 0)
        return PTR_OK;
    l->sphere = malloc(n * sizeof *l->sphere);
    l->keep = malloc(n * sizeof *l->keep);
    l->alias = malloc(n * sizeof *l->alias);
    double *scaled = malloc(n * sizeof *scaled);
    uint32_t *small = malloc(n * sizeof *small), *large = malloc(n * sizeof *large);
    if (!l->sphere || !l->keep || !l->alias || !scaled || !small || !large) {
        free(scaled), free(small), free(large);
        ptr_lights_free(l);
        return ptr_error_set(err, PTR_ERR_NOMEM, "cannot allocate a table of %zu emitters", n);
    }
    /* In the arrays' order, which the renderer's every structure shares
     * (the build's: see PtrSpheres), so the same emitter answers the same
     * random numbers whichever searches the spheres. */
    for (size_t i = 0; i < scene->spheres.count; i++)
        if (is_emitter(scene, (uint32_t)i)) {
            l->sphere[l->count++] = (uint32_t)i;
            l->total_power += sphere_power(scene, (uint32_t)i);
        }
    /* Vose's construction: columns below the mean are topped up from one
     * above it, which then counts as below or above in its turn. */
    size_t ns = 0, nl = 0;
    for (uint32_t i = 0; i < l->count; i++) {
        scaled[i] = sphere_power(scene, l->sphere[i]) * l->count / l->total_power;
        if (scaled[i] < 1.0)
            small[ns++] = i;
        else
            large[nl++] = i;
    }
    while (ns && nl) {
        uint32_t s = small[--ns], g = large[nl - 1];
        l->keep[s] = (float)scaled[s];
        l->alias[s] = g;
        scaled[g] -= 1.0 - scaled[s];
        if (scaled[g] < 1.0) {
            nl--;
            small[ns++] = g;
        }
    }
    /* What remains is 1 up to rounding. */
    while (nl) {
        uint32_t g = large[--nl];
        l->keep[g] = 1.0f, l->alias[g] = g;
    }
    while (ns) {
        uint32_t s = small[--ns];
        l->keep[s] = 1.0f, l->alias[s] = s;
    }
    free(scaled), free(small), free(large);
    return PTR_OK;
}

void ptr_lights_free(PtrLights *l)
{
    free(l->sphere);
    free(l->keep);
    free(l->alias);
    *l = (PtrLights){ 0 };
}

uint32_t ptr_lights_pick(const PtrLights *l, const uint32_t bits[2])
{
    /* All 32 bits choose the column: with thousands of emitters, 24 would
     * leave columns unequal by parts in 10^4. */
    uint32_t column = (uint32_t)(((uint64_t)bits[0] * l->count) >> 32);
    return (float)(bits[1] >> 8) * 0x1.0p-24f < l->keep[column] ? column : l->alias[column];
}

float ptr_lights_pick_pdf(const PtrLights *l, const PtrScene *scene, uint32_t sphere)
{
    return (float)(sphere_power(scene, sphere) / l->total_power);
}

PtrLightView ptr_light_view(PtrVec3 p, PtrVec3 c, float r, int own_side)
{
    if (own_side)
        return own_side > 0 ? PTR_LIGHT_UNSEEN : PTR_LIGHT_FROM_INSIDE;
    PtrVec3 d = v3_sub(c, p);
    return v3_dot(d, d) < r * r ? PTR_LIGHT_FROM_INSIDE : PTR_LIGHT_FROM_OUTSIDE;
}

/* 1 - cos of the half-angle of the cone the sphere subtends from distance^2
 * d2, computed as sin^2 / (1 + cos) so that small, far spheres keep their
 * digits. */
static float cone_width(float d2, float r)
{
    float sin2 = ptr_minf(1.0f, r * r / d2);
    return sin2 / (1.0f + sqrtf(1.0f - sin2));
}

/* An orthonormal basis around unit w (Duff et al. 2017, "Building an
 * Orthonormal Basis, Revisited"). */
static void basis(PtrVec3 w, PtrVec3 *t, PtrVec3 *b)
{
    float sign = copysignf(1.0f, w.z);
    float a = -1.0f / (sign + w.z), bxy = w.x * w.y * a;
    *t = v3(1.0f + sign * w.x * w.x * a, sign * bxy, -sign * w.x);
    *b = v3(bxy, sign + w.y * w.y * a, -w.y);
}

int ptr_light_sample(PtrLightView view, PtrVec3 p, PtrVec3 c, float r, const float u[2],
                     PtrVec3 *dir, float *distance, float *pdf)
{
    if (view == PTR_LIGHT_FROM_INSIDE) {
        PtrVec3 n = ptr_uniform_sphere(u[0], u[1]);
        PtrVec3 to = v3_sub(v3_madd(c, n, r), p);
        float d2 = v3_dot(to, to), d = sqrtf(d2);
        if (!(d > 0.0f))
            return 0;
        *dir = v3_scale(to, 1.0f / d);
        float cos_light = fabsf(v3_dot(n, *dir));
        if (!(cos_light > 0.0f))
            return 0;
        *distance = d;
        *pdf = d2 / (cos_light * 4.0f * PTR_PI * r * r);
        return 1;
    }
    if (view != PTR_LIGHT_FROM_OUTSIDE)
        return 0;
    PtrVec3 to = v3_sub(c, p);
    float d2 = v3_dot(to, to), d = sqrtf(d2);
    float width = cone_width(d2, r);
    float one_minus_cos = u[0] * width;
    float cos_theta = 1.0f - one_minus_cos;
    float sin_theta = sqrtf(ptr_maxf(0.0f, one_minus_cos * (2.0f - one_minus_cos)));
    float sin_phi, cos_phi;
    ptr_sincos_turns(u[1], &sin_phi, &cos_phi);
    PtrVec3 w = v3_scale(to, 1.0f / d), t, b;
    basis(w, &t, &b);
    *dir = v3_normalize(v3_add(v3_scale(w, cos_theta),
                               v3_add(v3_scale(t, sin_theta * cos_phi),
                                      v3_scale(b, sin_theta * sin_phi))));
    /* The near intersection; at the cone's rim the root vanishes. */
    *distance = d * cos_theta - sqrtf(ptr_maxf(0.0f, r * r - d2 * sin_theta * sin_theta));
    *pdf = 1.0f / (2.0f * PTR_PI * width);
    return width > 0.0f;
}

float ptr_light_pdf(PtrLightView view, PtrVec3 p, PtrVec3 c, float r, PtrVec3 dir, float t,
                    PtrVec3 n)
{
    if (view == PTR_LIGHT_FROM_INSIDE) {
        float cos_light = fabsf(v3_dot(n, dir));
        return cos_light > 0.0f ? t * t / (cos_light * 4.0f * PTR_PI * r * r) : INFINITY;
    }
    if (view != PTR_LIGHT_FROM_OUTSIDE)
        return 0.0f;
    PtrVec3 to = v3_sub(c, p);
    return 1.0f / (2.0f * PTR_PI * cone_width(v3_dot(to, to), r));
}
