/* The renderer converges to one answer, at the Monte Carlo rate:
 *
 * - renders with different seeds agree: 16 independent 16-spp renders with
 *   seeds 1..16 and 16 with seeds 101..116; for each 8x8 block and channel
 *   the two groups' means differ by z standard errors, and the sum of z^2
 *   over the cells follows chi^2 with as many degrees of freedom if the
 *   renderer does not depend on its seed beyond noise: the test fails in
 *   the 10^-6 upper tail. Cells without noise (sky seen only directly) must
 *   agree exactly instead;
 * - with independent numbers, the RMSE against a 4096-spp reference falls
 *   as spp^-1/2: the log-log slope over 1 to 64 spp is -0.5 +- 0.1;
 * - with Owen-scrambled Sobol' points (the default) it falls faster, where
 *   the pixel, lens and first-bounce integrals are smooth enough: the slope
 *   is below -0.55 (measured -0.65). */
#include <stdint.h>

#include "importer.h"
#include "render/render.h"
#include "test.h"

enum { SIZE = 32, BLOCK = 8, GROUP = 16 };

static PtrScene scene;
static PtrIsectTable isect;

static void render_with(PtrSamplerKind sampler, uint32_t spp, uint64_t seed, float *rgb)
{
    PtrRenderSettings settings = { .width = SIZE, .height = SIZE, .samples = spp, .seed = seed,
                                   .max_depth = 50, .sampler = sampler };
    PtrError err = { 0 };
    const PtrAccel accel = ptr_accel_brute(&isect, &scene);
    CHECK_INT(ptr_render(&scene, &accel, &settings, rgb, NULL, &err), PTR_OK);
}

static void render(uint32_t spp, uint64_t seed, float *rgb)
{
    render_with(PTR_SAMPLER_SOBOL, spp, seed, rgb);
}

/* Means of each 8x8 block and channel. */
static void block_means(const float *rgb, double *means)
{
    const int blocks = SIZE / BLOCK;
    for (int i = 0; i < blocks * blocks * 3; i++)
        means[i] = 0;
    for (int y = 0; y < SIZE; y++)
        for (int x = 0; x < SIZE; x++)
            for (int c = 0; c < 3; c++)
                means[((y / BLOCK) * blocks + x / BLOCK) * 3 + c] +=
                    rgb[3 * (y * SIZE + x) + c] / (double)(BLOCK * BLOCK);
}

static void test_seed_independence(void)
{
    enum { CELLS = (SIZE / BLOCK) * (SIZE / BLOCK) * 3 };
    static float rgb[SIZE * SIZE * 3];
    double sum[2][CELLS] = { { 0 } }, sum2[2][CELLS] = { { 0 } }, means[CELLS];
    for (int g = 0; g < 2; g++)
        for (int i = 0; i < GROUP; i++) {
            render(16, (uint64_t)(1 + 100 * g + i), rgb);
            block_means(rgb, means);
            for (int k = 0; k < CELLS; k++) {
                sum[g][k] += means[k];
                sum2[g][k] += means[k] * means[k];
            }
        }
    double chi2 = 0;
    int dof = 0;
    for (int k = 0; k < CELLS; k++) {
        double m[2], v[2];
        for (int g = 0; g < 2; g++) {
            m[g] = sum[g][k] / GROUP;
            v[g] = fmax(0.0, (sum2[g][k] - GROUP * m[g] * m[g]) / (GROUP - 1) / GROUP);
        }
        if (v[0] + v[1] < 1e-12 * (m[0] * m[0] + 1e-30)) {
            CHECK_NEAR(m[0], m[1], 1e-6 * fabs(m[0]));
            continue;
        }
        chi2 += (m[0] - m[1]) * (m[0] - m[1]) / (v[0] + v[1]);
        dof++;
    }
    /* Wilson-Hilferty: chi^2(k) quantile ~ k (1 - 2/9k + z sqrt(2/9k))^3,
     * z = 4.75 for a 10^-6 tail. */
    double w = 2.0 / (9.0 * dof), limit = dof * pow(1.0 - w + 4.75 * sqrt(w), 3.0);
    printf("seed independence: chi^2 = %.1f with %d degrees of freedom (limit %.1f)\n", chi2, dof,
           limit);
    CHECK(dof >= CELLS / 2);
    CHECK(chi2 < limit);
}

/* The log-log slope of RMSE against spp over 1 to 64 spp. */
static double convergence_slope(PtrSamplerKind sampler, const float *ref)
{
    static float img[SIZE * SIZE * 3];
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int n = 0;
    for (uint32_t spp = 1; spp <= 64; spp *= 2) {
        render_with(sampler, spp, 1, img);
        double se = 0;
        for (int i = 0; i < SIZE * SIZE * 3; i++)
            se += (double)(img[i] - ref[i]) * (img[i] - ref[i]);
        double x = log((double)spp), y = log(sqrt(se / (SIZE * SIZE * 3)));
        sx += x, sy += y, sxx += x * x, sxy += x * y, n++;
    }
    return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

static void test_convergence_rate(void)
{
    static float ref[SIZE * SIZE * 3];
    render(4096, 1000, ref);
    double independent = convergence_slope(PTR_SAMPLER_INDEPENDENT, ref);
    double sobol = convergence_slope(PTR_SAMPLER_SOBOL, ref);
    printf("convergence: RMSE ~ spp^%.3f (independent), spp^%.3f (sobol) over 1..64 spp\n",
           independent, sobol);
    CHECK_NEAR(independent, -0.5, 0.1);
    CHECK(sobol < -0.55);
}

int main(void)
{
    PtrStrings warnings = { 0 };
    PtrError err = { 0 };
    CHECK_INT(ptr_import_scene(PTR_SOURCE_DIR "/scenes/seed.gltf", NULL, &scene, &warnings, &err),
              PTR_OK);
    ptr_strings_free(&warnings);
    ptr_isect_init(&isect, PTR_KERNEL_AUTO, ptr_cpu_level(), scene.spheres.count, NULL);
    const TestCase cases[] = {
        TEST_CASE(test_seed_independence),
        TEST_CASE(test_convergence_rate),
    };
    TEST_RUN(cases);
    ptr_scene_free(&scene);
    return test_report();
}
