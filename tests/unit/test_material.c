/* Scattering: energy, reflection laws, Fresnel and total internal reflection. */
#include "render/material.h"
#include "sampling/rng.h"
#include "test.h"

static void test_schlick(void)
{
    /* Normal incidence: ((n1 - n2) / (n1 + n2))^2 = 0.04 for glass in air. */
    CHECK_NEAR(ptr_schlick(1.0f, 1.0f / 1.5f), 0.04, 1e-7);
    CHECK_NEAR(ptr_schlick(1.0f, 1.5f), 0.04, 1e-7);
    CHECK_FLOAT_EQ(ptr_schlick(0.0f, 1.0f / 1.5f), 1.0f); /* grazing: all reflected */
    CHECK_FLOAT_EQ(ptr_schlick(1.0f, 1.0f), 0.0f);        /* no interface */
}

/* Three uniform numbers for one scattering. */
static const float *draw(PtrRng *rng, float u[3])
{
    for (int i = 0; i < 3; i++)
        u[i] = ptr_rng_float(rng);
    return u;
}

static int is_unit(PtrVec3 v) { return fabs(v3_length(v) - 1.0) < 1e-5; }

static void test_energy_and_directions(void)
{
    PtrRng rng = ptr_rng_for_sample(3, 0, 0);
    float u[3];
    PtrVec3 n = v3(0, 1, 0);
    const PtrMaterial diffuse = { .kind = PTR_MATERIAL_DIFFUSE, .albedo = v3(0.9f, 0.5f, 0.1f) };
    const PtrMaterial metal = { .kind = PTR_MATERIAL_METAL, .albedo = v3(1, 0.8f, 0.6f),
                                .fuzz = 0.3f };
    const PtrMaterial glass = { .kind = PTR_MATERIAL_DIELECTRIC, .albedo = v3_splat(1), .ior = 1.5f };
    const PtrMaterial *all[] = { &diffuse, &metal, &glass };

    int bad_dir = 0, gained = 0, wrong_side = 0;
    double cos_sum = 0;
    const int n_samples = 200000;
    for (int i = 0; i < n_samples; i++) {
        PtrVec3 in = v3_normalize(v3(ptr_rng_float(&rng) - 0.5f, -ptr_rng_float(&rng) - 0.01f,
                                     ptr_rng_float(&rng) - 0.5f));
        for (int m = 0; m < 3; m++) {
            PtrVec3 out, att;
            if (!ptr_scatter(all[m], in, n, draw(&rng, u), &out, &att))
                continue;
            bad_dir += !is_unit(out);
            gained += att.x > all[m]->albedo.x || att.y > all[m]->albedo.y ||
                      att.z > all[m]->albedo.z;
            if (m < 2)
                wrong_side += v3_dot(out, n) <= 0.0f;
            if (m == 0)
                cos_sum += v3_dot(out, n);
        }
    }
    CHECK_INT(bad_dir, 0);
    CHECK_INT(gained, 0);
    CHECK_INT(wrong_side, 0);
    /* Lambertian: E[cos theta] = 2/3, standard deviation sqrt(1/2 - 4/9) = 0.236;
     * the standard error over 2e5 samples is 5.3e-4; 5 sigma is 2.7e-3. */
    CHECK_NEAR(cos_sum / n_samples, 2.0 / 3.0, 2.7e-3);
}

static void test_mirror(void)
{
    PtrRng rng = ptr_rng_for_sample(4, 0, 0);
    float u[3];
    const PtrMaterial mirror = { .kind = PTR_MATERIAL_METAL, .albedo = v3_splat(0.7f) };
    PtrVec3 in = v3_normalize(v3(1, -2, 0.5f)), out, att;
    CHECK(ptr_scatter(&mirror, in, v3(0, 1, 0), draw(&rng, u), &out, &att));
    CHECK_NEAR(out.x, in.x, 1e-6);
    CHECK_NEAR(out.y, -in.y, 1e-6);
    CHECK_NEAR(out.z, in.z, 1e-6);
    CHECK_FLOAT_EQ(att.y, 0.7f);

    /* A heavily fuzzed metal at grazing incidence absorbs what points inward. */
    const PtrMaterial rough = { .kind = PTR_MATERIAL_METAL, .albedo = v3_splat(1), .fuzz = 1 };
    PtrVec3 grazing = v3_normalize(v3(1, -0.05f, 0));
    int absorbed = 0;
    for (int i = 0; i < 1000; i++)
        absorbed += !ptr_scatter(&rough, grazing, v3(0, 1, 0), draw(&rng, u), &out, &att);
    CHECK(absorbed > 100 && absorbed < 900);
}

static void test_dielectric(void)
{
    PtrRng rng = ptr_rng_for_sample(5, 0, 0);
    float u[3];
    const PtrMaterial glass = { .kind = PTR_MATERIAL_DIELECTRIC, .albedo = v3_splat(1), .ior = 1.5f };
    PtrVec3 outward = v3(0, 1, 0), out, att;

    /* From inside, beyond the critical angle asin(1/1.5) = 41.8 degrees, every
     * ray is reflected back inside. */
    float theta = 45.0f * PTR_PI / 180.0f;
    PtrVec3 inside = v3(sinf(theta), cosf(theta), 0); /* travelling outward */
    int reflected = 0;
    for (int i = 0; i < 1000; i++) {
        ptr_scatter(&glass, inside, outward, draw(&rng, u), &out, &att);
        reflected += out.y < 0 && fabsf(out.x - inside.x) < 1e-6f;
    }
    CHECK_INT(reflected, 1000);

    /* From outside at 30 degrees, refracted rays obey Snell's law, and the
     * share reflected is Schlick's reflectance (binomial, 5 sigma). */
    theta = 30.0f * PTR_PI / 180.0f;
    PtrVec3 in = v3(sinf(theta), -cosf(theta), 0);
    int refracted = 0, snell_ok = 0;
    const int n = 100000;
    for (int i = 0; i < n; i++) {
        ptr_scatter(&glass, in, outward, draw(&rng, u), &out, &att);
        if (out.y < 0) {
            refracted++;
            snell_ok += fabsf(out.x - sinf(theta) / 1.5f) < 1e-6f;
        }
    }
    CHECK_INT(snell_ok, refracted);
    double r = ptr_schlick(cosf(theta), 1.0f / 1.5f);
    CHECK_NEAR((double)(n - refracted) / n, r, 5 * sqrt(r * (1 - r) / n));
}

/* The diffuse density is the one scattering draws from and eval / pdf is the
 * attenuation scattering reports, for every sample; and the directions follow
 * that density: under cos / pi, cos theta < 0.5 has probability 0.25. */
static void test_diffuse_density(void)
{
    PtrRng rng = ptr_rng_for_sample(6, 0, 0);
    float u[3];
    const PtrMaterial diffuse = { .kind = PTR_MATERIAL_DIFFUSE, .albedo = v3(0.9f, 0.5f, 0.1f) };
    PtrVec3 n = v3_normalize(v3(0.3f, 1, -0.2f)), in = v3_neg(n), out, att;
    int wrong = 0, below = 0;
    double under_half = 0;
    const int count = 100000;
    for (int i = 0; i < count; i++) {
        ptr_scatter(&diffuse, in, n, draw(&rng, u), &out, &att);
        float pdf = ptr_diffuse_pdf(n, out);
        below += !(pdf > 0.0f);
        PtrVec3 eval = ptr_diffuse_eval(&diffuse, n, out);
        wrong += fabsf(eval.x / pdf - att.x) > 1e-6f || fabsf(eval.z / pdf - att.z) > 1e-6f;
        wrong += fabsf(pdf * PTR_PI - v3_dot(n, out)) > 1e-6f;
        under_half += v3_dot(n, out) < 0.5f;
    }
    CHECK_INT(wrong, 0);
    CHECK_INT(below, 0);
    /* P(cos theta > c) = 1 - c^2 (binomial, 5 sigma). */
    CHECK_NEAR(under_half / count, 0.25, 5 * sqrt(0.25 * 0.75 / count));
}

/* What light sampling asks of a material: the density and BSDF of a
 * diffuse surface are the diffuse formulas, and a mirror's, fuzzy metal's
 * and glass's are 0 (they scatter without a density light sampling could
 * weigh), as ptr_material_has_density says of each kind. */
static void test_material_density(void)
{
    PtrRng rng = ptr_rng_for_sample(7, 0, 0);
    const PtrMaterial materials[] = {
        { .kind = PTR_MATERIAL_DIFFUSE, .albedo = v3(0.9f, 0.5f, 0.1f) },
        { .kind = PTR_MATERIAL_METAL, .albedo = v3(1, 0.8f, 0.6f) },
        { .kind = PTR_MATERIAL_METAL, .albedo = v3(1, 0.8f, 0.6f), .fuzz = 0.3f },
        { .kind = PTR_MATERIAL_DIELECTRIC, .albedo = v3_splat(1), .ior = 1.5f },
    };
    enum { KINDS = sizeof materials / sizeof materials[0] };
    PtrVec3 n = v3_normalize(v3(0.3f, 1, -0.2f));
    int cases = 0, wrong = 0, with_density[KINDS] = { 0 };
    for (int i = 0; i < 1000; i++) {
        PtrVec3 out = ptr_uniform_sphere(ptr_rng_float(&rng), ptr_rng_float(&rng));
        for (int k = 0; k < KINDS; k++) {
            const PtrMaterial *m = &materials[k];
            float pdf = ptr_material_pdf(m, n, out);
            PtrVec3 eval = ptr_material_eval(m, n, out);
            int diffuse = m->kind == PTR_MATERIAL_DIFFUSE;
            float want_pdf = diffuse ? ptr_diffuse_pdf(n, out) : 0.0f;
            PtrVec3 want_eval = diffuse ? ptr_diffuse_eval(m, n, out) : v3_splat(0.0f);
            wrong += pdf != want_pdf || eval.x != want_eval.x || eval.y != want_eval.y ||
                     eval.z != want_eval.z;
            with_density[k] += pdf > 0.0f;
            cases++;
        }
    }
    CHECK_INT(cases, 4000);
    CHECK_INT(wrong, 0);
    for (int k = 0; k < KINDS; k++)
        CHECK_INT(with_density[k] > 0, ptr_material_has_density(materials[k].kind));
}

int main(void)
{
    const TestCase cases[] = {
        TEST_CASE(test_diffuse_density),
        TEST_CASE(test_material_density),
        TEST_CASE(test_schlick),
        TEST_CASE(test_energy_and_directions),
        TEST_CASE(test_mirror),
        TEST_CASE(test_dielectric),
    };
    TEST_RUN(cases);
    return test_report();
}
