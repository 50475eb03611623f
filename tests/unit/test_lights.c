/* Light sampling of emissive spheres.
 *
 * - The alias table picks each emitter with probability power / total.
 * - A sampled direction's density is the one ptr_light_pdf gives it, and it
 *   meets the sphere at the distance reported, from outside and inside.
 * - Closed form (lit_ground.h): a diffuse ground (albedo a, radius 1000) lit
 *   by one sphere of radiance L and radius r under a black sky shows
 *   a L (r/d)^2 cos theta wherever the emitter is wholly above the horizon.
 *   At 64 spp every pixel must be within 2% (see test_closed_form for why).
 * - Unbiasedness: the defaults (Sobol', light sampling, MIS) and the plain
 *   estimator (independent numbers, no light sampling) agree on a scene with
 *   glass, metal, diffuse and emitters (some of them reflective): chi^2 over
 *   8x8 blocks of the two means, with variances from 16 seeds each, below
 *   its 10^-6 tail. */
#include <stdint.h>

#include "lit_ground.h"
#include "render/camera.h"
#include "render/lights.h"
#include "render/render.h"
#include "sampling/rng.h"
#include "test.h"

static uint32_t add_material(PtrScene *s, PtrMaterial m)
{
    uint32_t index;
    CHECK_INT(ptr_scene_add_material(s, &m, &index, NULL), PTR_OK);
    return index;
}

static void test_alias_table(void)
{
    PtrScene s;
    ptr_scene_init(&s);
    uint32_t dull = add_material(&s, (PtrMaterial){ .kind = PTR_MATERIAL_DIFFUSE });
    const float strengths[] = { 1, 7, 0.25f, 3, 100, 0.5f };
    uint32_t mats[6];
    for (int i = 0; i < 6; i++)
        mats[i] = add_material(&s, (PtrMaterial){ .kind = PTR_MATERIAL_DIFFUSE,
                                                  .emission = v3(strengths[i], 0, 1) });
    for (int i = 0; i < 40; i++)
        CHECK_INT(ptr_scene_add_sphere(&s, v3((float)i, 0, 0), 0.1f + 0.05f * (float)(i % 5),
                                       i % 3 ? mats[i % 6] : dull, NULL), PTR_OK);
    PtrLights l;
    PtrError err = { 0 };
    CHECK_INT(ptr_lights_init(&l, &s, &err), PTR_OK);
    CHECK_INT(l.count, 26);
    /* The probability of each column's outcome, from the table. */
    double implied[40] = { 0 }, worst = 0, total = 0;
    for (uint32_t c = 0; c < l.count; c++) {
        implied[c] += l.keep[c] / (double)l.count;
        implied[l.alias[c]] += (1.0 - l.keep[c]) / (double)l.count;
    }
    for (uint32_t c = 0; c < l.count; c++) {
        double want = ptr_lights_pick_pdf(&l, &s, l.sphere[c]);
        worst = fmax(worst, fabs(implied[c] - want) / want);
        total += want;
    }
    printf("alias table: worst relative error of a pick probability %.2g\n", worst);
    CHECK(worst < 1e-6);
    CHECK_NEAR(total, 1.0, 1e-6);
    ptr_lights_free(&l);
    ptr_scene_free(&s);
}

static void test_sample_pdf(void)
{
    PtrRng rng = ptr_rng_for_sample(21, 0, 0);
    const PtrVec3 c = v3(1, 2, -3);
    const float r = 0.5f;
    const PtrVec3 points[] = { v3(4, 0, 1), v3(1, 2.6f, -3), v3(1.1f, 2.1f, -3.2f), v3(50, 30, 0) };
    int bad_pdf = 0, bad_point = 0, samples = 0;
    for (size_t k = 0; k < sizeof points / sizeof points[0]; k++) {
        PtrLightView view = ptr_light_view(points[k], c, r, 0);
        CHECK_INT(view, k == 2 ? PTR_LIGHT_FROM_INSIDE : PTR_LIGHT_FROM_OUTSIDE);
        for (int i = 0; i < 2000; i++) {
            float u[2] = { ptr_rng_float(&rng), ptr_rng_float(&rng) }, t, pdf;
            PtrVec3 dir;
            if (!ptr_light_sample(view, points[k], c, r, u, &dir, &t, &pdf))
                continue;
            samples++;
            PtrVec3 q = v3_madd(points[k], dir, t);
            bad_point += fabsf(v3_length(v3_sub(q, c)) - r) > 2e-3f * r;
            PtrVec3 n = v3_normalize(v3_sub(q, c));
            float again = ptr_light_pdf(view, points[k], c, r, dir, t, n);
            bad_pdf += fabsf(again - pdf) > 1e-3f * pdf;
        }
    }
    CHECK(samples > 7900);
    CHECK_INT(bad_point, 0);
    CHECK_INT(bad_pdf, 0);
    /* A point on the sphere's outside cannot see it. */
    CHECK_INT(ptr_light_view(v3(1, 2.5f, -3), c, r, 1), PTR_LIGHT_UNSEEN);
}

enum { SIZE = 32 };

static float *render(const PtrScene *s, PtrRenderSettings settings)
{
    PtrIsectTable isect;
    ptr_isect_init(&isect, PTR_KERNEL_AUTO, ptr_cpu_level(), s->spheres.count, NULL);
    float *rgb = malloc((size_t)settings.width * settings.height * 3 * sizeof *rgb);
    PtrError err = { 0 };
    const PtrAccel accel = ptr_accel_brute(&isect, s);
    CHECK_INT(ptr_render(s, &accel, &settings, rgb, NULL, &err), PTR_OK);
    return rgb;
}

/* The tolerance, 2%: what remains at 64 spp is the pixel footprint (the
 * value varies by a few per cent across a pixel, and the centre stands for
 * the pixel's mean only to second order: about 0.1%), the cosine across the
 * emitter's small cone, and the rare scattered rays that find the emitter at
 * a small MIS weight; measured: worst 0.35% over seeds 1 to 4.
 * Without light sampling the same render is off by far more than 5%, the
 * bound the estimator was built to meet. */
static void test_closed_form(void)
{
    PtrIsectTable isect;
    ptr_isect_init(&isect, PTR_KERNEL_AUTO, ptr_cpu_level(), 2, NULL);
    PtrRenderSettings settings = { .samples = 64, .max_depth = 50 };
    double worst = 0;
    for (uint64_t seed = 1; seed <= 4; seed++) {
        settings.seed = seed;
        worst = fmax(worst, lit_ground_errors(1000, PTR_BUILD_DEFAULT, &isect, settings).worst);
    }
    settings.sampler = PTR_SAMPLER_INDEPENDENT;
    settings.direct_lighting = PTR_OFF;
    double plain = lit_ground_errors(1000, PTR_BUILD_DEFAULT, &isect, settings).worst;
    printf("closed form at 64 spp: worst relative error %.4f (seeds 1-4); without light "
           "sampling %.2f\n", worst, plain);
    CHECK(worst <= 0.02);
    CHECK(plain > 0.05);
}

/* Ground, glass, mirror, fuzzed metal and diffuse spheres, lit by three
 * emitters large enough for the plain estimator to find them. */
static PtrScene mixed_scene(void)
{
    PtrScene s;
    ptr_scene_init(&s);
    const struct {
        float x, y, z, r;
        PtrMaterial m;
    } spheres[] = {
        { 0, -1000, 0, 1000, { .kind = PTR_MATERIAL_DIFFUSE, .albedo = v3_splat(0.5f) } },
        { 0, 1, 0, 1, { .kind = PTR_MATERIAL_DIELECTRIC, .albedo = v3_splat(1), .ior = 1.5f } },
        { -2.2f, 1, 0, 1, { .kind = PTR_MATERIAL_METAL, .albedo = v3(0.9f, 0.8f, 0.7f) } },
        { 2.2f, 1, 0, 1, { .kind = PTR_MATERIAL_METAL, .albedo = v3_splat(0.8f), .fuzz = 0.3f } },
        { 1, 0.4f, 2, 0.4f, { .kind = PTR_MATERIAL_DIFFUSE, .albedo = v3(0.2f, 0.5f, 0.8f) } },
        { -1.5f, 3, 1, 0.6f, { .kind = PTR_MATERIAL_DIFFUSE, .emission = v3(4, 3, 2) } },
        { 2, 2.5f, -1, 0.5f, { .kind = PTR_MATERIAL_DIFFUSE, .albedo = v3_splat(0.5f),
                               .emission = v3(2, 3, 5) } },
        { 0, 4, 3, 0.8f, { .kind = PTR_MATERIAL_METAL, .albedo = v3_splat(0.5f),
                           .emission = v3_splat(1.5f) } },
    };
    for (size_t i = 0; i < sizeof spheres / sizeof spheres[0]; i++)
        CHECK_INT(ptr_scene_add_sphere(&s, v3(spheres[i].x, spheres[i].y, spheres[i].z),
                                       spheres[i].r, add_material(&s, spheres[i].m), NULL), PTR_OK);
    s.sky.kind = PTR_SKY_BLACK;
    s.camera = (PtrCamera){ .lookfrom = v3(0, 2.5f, 7), .lookat = v3(0, 1, 0), .up = v3(0, 1, 0),
                            .vfov_deg = 50, .focus_distance = 7 };
    return s;
}

enum { BLOCK = 8, GROUP = 16, CELLS = (SIZE / BLOCK) * (SIZE / BLOCK) * 3 };

/* Mean and variance of the mean of each 8x8 block and channel over GROUP
 * renders with seeds first .. first + GROUP - 1. */
static void block_stats(const PtrScene *s, PtrRenderSettings settings, uint64_t first,
                        double *mean, double *var)
{
    double sum[CELLS] = { 0 }, sum2[CELLS] = { 0 };
    for (int g = 0; g < GROUP; g++) {
        settings.seed = first + (uint64_t)g;
        float *rgb = render(s, settings);
        double cell[CELLS] = { 0 };
        for (int y = 0; y < SIZE; y++)
            for (int x = 0; x < SIZE; x++)
                for (int c = 0; c < 3; c++)
                    cell[((y / BLOCK) * (SIZE / BLOCK) + x / BLOCK) * 3 + c] +=
                        rgb[3 * (y * SIZE + x) + c] / (BLOCK * BLOCK);
        for (int k = 0; k < CELLS; k++)
            sum[k] += cell[k], sum2[k] += cell[k] * cell[k];
        free(rgb);
    }
    for (int k = 0; k < CELLS; k++) {
        mean[k] = sum[k] / GROUP;
        var[k] = fmax(0.0, (sum2[k] - GROUP * mean[k] * mean[k]) / (GROUP - 1) / GROUP);
    }
}

static void test_unbiased(void)
{
    PtrScene s = mixed_scene();
    PtrRenderSettings settings = { .width = SIZE, .height = SIZE, .samples = 32, .max_depth = 50 };
    double m[2][CELLS], v[2][CELLS];
    block_stats(&s, settings, 1, m[0], v[0]);
    settings.sampler = PTR_SAMPLER_INDEPENDENT;
    settings.direct_lighting = PTR_OFF;
    block_stats(&s, settings, 101, m[1], v[1]);
    double chi2 = 0, variance_ratio = 0;
    for (int k = 0; k < CELLS; k++) {
        chi2 += (m[0][k] - m[1][k]) * (m[0][k] - m[1][k]) / (v[0][k] + v[1][k]);
        variance_ratio += v[0][k] / v[1][k] / CELLS;
    }
    /* Wilson-Hilferty, z = 4.75 for a 10^-6 tail. */
    double w = 2.0 / (9.0 * CELLS), limit = CELLS * pow(1.0 - w + 4.75 * sqrt(w), 3.0);
    printf("unbiased: chi^2 = %.1f with %d degrees of freedom (limit %.1f); the defaults' "
           "variance is %.2f of the plain estimator's\n", chi2, CELLS, limit, variance_ratio);
    CHECK(chi2 < limit);
    ptr_scene_free(&s);
}

int main(void)
{
    const TestCase cases[] = {
        TEST_CASE(test_alias_table),
        TEST_CASE(test_sample_pdf),
        TEST_CASE(test_closed_form),
        TEST_CASE(test_unbiased),
    };
    TEST_RUN(cases);
    return test_report();
}
