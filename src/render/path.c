#include "render/path.h"

#include <math.h>

#include "accel/spawn.h"

void ptr_path_surface(const PtrPathJob *job, const PtrRay *ray, const PtrHit *hit,
                      PtrVec3 *point, PtrVec3 *normal)
{
    const PtrScene *scene = job->scene;
    const PtrSpheres *spheres = &scene->spheres;
    float fixed_tmin = job->settings->fixed_tmin;
    if (ptr_path_in_double(job, hit->sphere)) {
        ptr_huge_surface(scene, ray, hit, point, normal);
        return;
    }
    PtrVec3 org = v3(ray->org[0], ray->org[1], ray->org[2]);
    PtrVec3 dir = v3(ray->dir[0], ray->dir[1], ray->dir[2]);
    ptr_sphere_surface(ptr_sphere_centre(spheres, hit->sphere), spheres->radius[hit->sphere], org,
                       dir, hit->t, point, normal);
    if (fixed_tmin > 0.0f)
        *point = v3_madd(org, dir, hit->t);
}

PtrRay ptr_path_leave(const PtrPathJob *job, uint32_t sphere, PtrVec3 point,
                      PtrVec3 outward_normal, PtrVec3 dir)
{
    const PtrSpheres *spheres = &job->scene->spheres;
    float tmin = job->settings->fixed_tmin;
    if (ptr_path_in_double(job, sphere))
        return ptr_huge_spawn_ray(job->scene, sphere, point, dir);
    if (tmin > 0.0f)
        return (PtrRay){ { point.x, point.y, point.z }, tmin, { dir.x, dir.y, dir.z }, INFINITY };
    return ptr_spawn_ray(ptr_sphere_centre(spheres, sphere), spheres->radius[sphere],
                         outward_normal, dir);
}

/* Whether a shadow ray reaches the emitter: the one closest-hit query of a
 * shadow ray, through the intersector camera rays use. Its tmax lies just
 * beyond the point sampled on the emitter, so a miss or a hit on the emitter
 * itself means nothing stands in between. */
static int reaches_emitter(const PtrPathJob *job, const PtrRay *ray, uint32_t emitter,
                           uint64_t *rays)
{
    PtrHit hit;
    ++*rays;
    return !ptr_trace(job->accel, ray, &hit) || hit.sphere == emitter;
}

/* Power heuristic (Veach), written so that an infinite density on either
 * side gives 0 or 1 rather than NaN. */
static float power_heuristic(float pdf, float other_pdf)
{
    float ratio = other_pdf / pdf;
    return 1.0f / (1.0f + ratio * ratio);
}

static PtrLightView view_from(const PtrLitVertex *v, const PtrSpheres *spheres, uint32_t emitter)
{
    return ptr_light_view(v->point, ptr_sphere_centre(spheres, emitter), spheres->radius[emitter],
                          v->sphere == emitter ? v->side : 0);
}

PtrVec3 ptr_path_sample_emitter(const PtrPathJob *job, const PtrSampler *sampler, int bounce,
                                const PtrMaterial *m, const PtrLitVertex *at, PtrVec3 n,
                                PtrVec3 outward_normal, uint64_t *rays)
{
    const PtrScene *scene = job->scene;
    const PtrSpheres *spheres = &scene->spheres;
    uint32_t pick[2];
    float u[2];
    ptr_sampler_2d_bits(sampler, ptr_bounce_dim(bounce, PTR_SLOT_LIGHT_PICK), pick);
    ptr_sampler_2d(sampler, ptr_bounce_dim(bounce, PTR_SLOT_LIGHT_POINT), u);
    uint32_t emitter = job->lights.sphere[ptr_lights_pick(&job->lights, pick)];
    PtrVec3 dir;
    float distance, pdf;
    if (!ptr_light_sample(view_from(at, spheres, emitter), at->point,
                          ptr_sphere_centre(spheres, emitter), spheres->radius[emitter], u, &dir,
                          &distance, &pdf))
        return v3_splat(0.0f);
    pdf *= ptr_lights_pick_pdf(&job->lights, scene, emitter);
    float scatter_pdf = ptr_material_pdf(m, n, dir);
    if (!(scatter_pdf > 0.0f) || !(pdf > 0.0f))
        return v3_splat(0.0f);
    PtrRay shadow = ptr_path_leave(job, at->sphere, at->point, outward_normal, dir);
    shadow.tmax = ptr_maxf(distance * 1.001f, 2.0f * shadow.tmin);
    if (!reaches_emitter(job, &shadow, emitter, rays))
        return v3_splat(0.0f);
    PtrVec3 emission = scene->materials[ptr_sphere_material(spheres, emitter)].emission;
    float weight = power_heuristic(pdf, scatter_pdf) / pdf;
    return v3_scale(v3_mul(ptr_material_eval(m, n, dir), emission), weight);
}

float ptr_path_emission_weight(const PtrPathJob *job, const PtrLitVertex *from, uint32_t emitter,
                               PtrVec3 dir, PtrVec3 point, PtrVec3 normal)
{
    const PtrSpheres *spheres = &job->scene->spheres;
    float light_pdf = ptr_light_pdf(view_from(from, spheres, emitter), from->point,
                                    ptr_sphere_centre(spheres, emitter), spheres->radius[emitter],
                                    dir, v3_length(v3_sub(point, from->point)), normal);
    if (!(light_pdf > 0.0f))
        return 1.0f;
    light_pdf *= ptr_lights_pick_pdf(&job->lights, job->scene, emitter);
    return power_heuristic(from->scatter_pdf, light_pdf);
}

/* Adaptive sampling's estimate of a pixel's remaining error, in the manner
 * of Cycles: the mean of all its samples against the mean of its odd ones,
 * summed over channels, relative to the square root of the brightness (the
 * eye forgives noise in bright pixels in about that proportion). */
static double pixel_error(const double *acc, int transparent)
{
    double n = acc[PTR_ACCUM_COUNT], half = floor(n / 2), difference = 0, brightness = 0;
    for (int c = 0; c < 3; c++) {
        double all = acc[PTR_ACCUM_SUM + c] / n;
        difference += fabs(all - acc[PTR_ACCUM_ODD + c] / half);
        brightness += all;
    }
    /* With a transparent background, alpha is a fourth channel: an edge
     * against it is noisy in coverage even where its colour is black. */
    if (transparent) {
        double all = acc[PTR_ACCUM_COVERED] / n;
        difference += fabs(all - acc[PTR_ACCUM_COVERED_ODD] / half);
        brightness += all;
    }
    return difference / (1e-4 + sqrt(brightness));
}

static void add_v3(double *sum, PtrVec3 v)
{
    sum[0] += v.x;
    sum[1] += v.y;
    sum[2] += v.z;
}

void ptr_path_accumulate(const PtrRenderSettings *s, double *acc, uint32_t index, PtrVec3 l,
                         int covered, const PtrPathPass *pass)
{
    if (s->transparent && !covered)
        l = v3_splat(0.0f);
    /* A transparent background leaves the sky out of the passes too. */
    if (s->passes && !(s->transparent && !covered)) {
        add_v3(acc + PTR_ACCUM_ALBEDO, pass->albedo);
        add_v3(acc + PTR_ACCUM_NORMAL, pass->normal);
    }
    acc[PTR_ACCUM_COVERED] += covered;
    if (index & 1)
        acc[PTR_ACCUM_COVERED_ODD] += covered;
    add_v3(acc + PTR_ACCUM_SUM, l);
    if (index & 1)
        add_v3(acc + PTR_ACCUM_ODD, l);
    acc[PTR_ACCUM_COUNT] += 1;
    uint32_t taken = index + 1;
    if (s->noise_threshold > 0 && taken >= s->min_samples && taken % PTR_ADAPTIVE_STEP == 0 &&
        pixel_error(acc, s->transparent) < s->noise_threshold)
        acc[PTR_ACCUM_STOPPED] = 1;
}
