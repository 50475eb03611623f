/* The Sobol' sampler's structure, exactly:
 *
 * - the first 2^k samples of a pixel, in every pair of dimensions, are a
 *   (0,k,2)-net: each of the 2^k elementary intervals of every shape
 *   2^-a x 2^-(k-a) holds exactly one point (k up to 12), and so is every
 *   later aligned block of 2^k samples (which also checks the second
 *   dimension's generator: any other matrix breaks some net);
 * - numbers are a pure function of (seed, pixel, index, dimension), and
 *   change with each of them;
 * - the pairs of one sample are scrambled apart (padding works): no two
 *   pairs repeat each other's points. */
#include <stdint.h>

#include "sampling/sampler.h"
#include "test.h"

/* Whether points first .. first + 2^k - 1 of the pair are a (0,k,2)-net. */
static int is_net(uint64_t seed, uint64_t pixel, uint32_t dim, uint32_t first, int k)
{
    uint32_t n = 1u << k;
    static uint32_t xs[1 << 12], ys[1 << 12];
    static unsigned char seen[1 << 12];
    for (uint32_t i = 0; i < n; i++) {
        PtrSampler s = ptr_sampler_for_sample(PTR_SAMPLER_SOBOL, seed, pixel, first + i);
        uint32_t bits[2];
        ptr_sampler_2d_bits(&s, dim, bits);
        xs[i] = bits[0], ys[i] = bits[1];
    }
    for (int a = 0; a <= k; a++) {
        memset(seen, 0, n);
        for (uint32_t i = 0; i < n; i++) {
            uint32_t cx = a ? xs[i] >> (32 - a) : 0, cy = k - a ? ys[i] >> (32 - (k - a)) : 0;
            uint32_t cell = (cx << (k - a)) | cy;
            if (seen[cell]++)
                return 0;
        }
    }
    return 1;
}

static void test_nets(void)
{
    int bad = 0, checked = 0;
    for (uint64_t pixel = 0; pixel < 5; pixel++)
        for (uint32_t dim = 0; dim < 12; dim += 3)
            for (int k = 0; k <= 12; k++) {
                bad += !is_net(7, pixel * 977, dim, 0, k);
                bad += !is_net(7, pixel * 977, dim, 3u << k, k);
                checked += 2;
            }
    printf("nets: %d of %d blocks are (0,k,2)-nets\n", checked - bad, checked);
    CHECK_INT(bad, 0);
}

static void test_pure_function(void)
{
    uint32_t a[2], b[2], c[2];
    PtrSampler s = ptr_sampler_for_sample(PTR_SAMPLER_SOBOL, 3, 1234, 17);
    ptr_sampler_2d_bits(&s, 5, a);
    ptr_sampler_2d_bits(&s, 5, b);
    CHECK(a[0] == b[0] && a[1] == b[1]);
    const PtrSampler others[] = {
        ptr_sampler_for_sample(PTR_SAMPLER_SOBOL, 4, 1234, 17),
        ptr_sampler_for_sample(PTR_SAMPLER_SOBOL, 3, 1235, 17),
        ptr_sampler_for_sample(PTR_SAMPLER_SOBOL, 3, 1234, 18),
        ptr_sampler_for_sample(PTR_SAMPLER_INDEPENDENT, 3, 1234, 17),
    };
    for (size_t i = 0; i < sizeof others / sizeof others[0]; i++) {
        ptr_sampler_2d_bits(&others[i], 5, c);
        CHECK(c[0] != a[0] && c[1] != a[1]);
    }
    ptr_sampler_2d_bits(&s, 6, c);
    CHECK(c[0] != a[0] && c[1] != a[1]);
}

/* Two pairs of the same 64 samples share no point coordinate: without
 * per-pair scrambling and shuffling every pair would be the same net. */
static void test_pairs_differ(void)
{
    int same = 0;
    for (uint32_t i = 0; i < 64; i++) {
        PtrSampler s = ptr_sampler_for_sample(PTR_SAMPLER_SOBOL, 1, 42, i);
        uint32_t p[2], q[2];
        ptr_sampler_2d_bits(&s, 2, p);
        ptr_sampler_2d_bits(&s, 3, q);
        same += p[0] >> 20 == q[0] >> 20 && p[1] >> 20 == q[1] >> 20;
    }
    /* Independent 12-bit cells coincide with probability 2^-24 each. */
    CHECK_INT(same, 0);
}

/* Floats are the 32-bit fractions' top 24 bits, in [0, 1). */
static void test_floats(void)
{
    int bad = 0;
    for (uint32_t i = 0; i < 4096; i++)
        for (int kind = 0; kind < 2; kind++) {
            PtrSampler s = ptr_sampler_for_sample((PtrSamplerKind)kind, 9, 5, i);
            uint32_t bits[2];
            float u[2];
            ptr_sampler_2d_bits(&s, 4, bits);
            ptr_sampler_2d(&s, 4, u);
            for (int c = 0; c < 2; c++)
                bad += !(u[c] >= 0.0f && u[c] < 1.0f) || u[c] != (float)(bits[c] >> 8) * 0x1p-24f;
        }
    CHECK_INT(bad, 0);
}

int main(void)
{
    test_nets();
    test_pure_function();
    test_pairs_differ();
    test_floats();
    return test_report();
}
