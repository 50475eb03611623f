/* The Sobol' sampler's structure, exactly:
 *
 * - the first 2^k samples of a pixel, in every pair of dimensions, are a
 *   (0,k,2)-net: each of the 2^k elementary intervals of every shape
 *   2^-a x 2^-(k-a) holds exactly one point (k up to 12), and so is every
 *   later aligned block of 2^k samples (which also checks the second
 *   dimension's generator: any other matrix breaks some net);
 * - the unscrambled sequence is Sobol's: the first dimension is the van der
 *   Corput radical inverse, the second has the published direction numbers
 *   (Joe and Kuo's dimension 2: polynomial x + 1, m = 1, 3, 5, 15, ...),
 *   both against naive implementations written here;
 * - the scramble is nested (Owen): a point's scrambled first k bits depend
 *   on its first k bits only, and permute them;
 * - numbers change with each of seed, pixel, index and dimension;
 * - the pairs of one sample are scrambled apart (padding works): no two
 *   pairs repeat each other's points. */
#include <stdint.h>

#include "sampling/rng.h"
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
    CHECK_INT(checked, 5 * 4 * 13 * 2);
    CHECK_INT(bad, 0);
}

/* The radical inverse in base 2, digit by digit. */
static uint32_t naive_van_der_corput(uint32_t index)
{
    uint32_t x = 0;
    for (int digit = 0; digit < 32; digit++)
        if (index >> digit & 1)
            x |= 0x80000000u >> digit;
    return x;
}

/* Sobol's second dimension from its direction numbers: v_k = m_k / 2^k with
 * m_1 = 1 and, for the polynomial x + 1, m_k = 2 m_(k-1) xor m_(k-1); point
 * index is the xor of v_k over the index's set bits k - 1. */
static uint32_t naive_sobol_second(uint32_t index)
{
    uint32_t m = 1, x = 0;
    for (int k = 1; k <= 32; k++) {
        if (index >> (k - 1) & 1)
            x ^= m << (32 - k);
        m = (m << 1) ^ m;
    }
    return x;
}

static void test_unscrambled_sobol(void)
{
    /* The first eight points of the second dimension, in index order. */
    const double published[8] = { 0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875 };
    for (uint32_t i = 0; i < 8; i++)
        CHECK_FLOAT_EQ(naive_sobol_second(i) * 0x1p-32, published[i]);
    int wrong = 0, checked = 0;
    PtrRng rng = ptr_rng_for_sample(2, 0, 0);
    for (uint32_t n = 0; n < (1u << 16) + 4096; n++, checked++) {
        /* Every index below 2^16, then random ones of all 32 bits. */
        uint32_t i = n < (1u << 16) ? n : (uint32_t)ptr_rng_next(&rng);
        wrong += ptr_reverse_bits(i) != naive_van_der_corput(i);
        wrong += ptr_reverse_bits(ptr_sobol_second_reversed(i)) != naive_sobol_second(i);
    }
    CHECK_INT(checked, (1u << 16) + 4096);
    CHECK_INT(wrong, 0);
}

/* ptr_laine_karras scrambles a bit-reversed fraction: its low k bits are the
 * fraction's first k. Nested scrambling maps each elementary interval of
 * length 2^-k to one such interval as a whole: the low k bits out depend on
 * the low k bits in only, and, as they cover all 2^k intervals, permute
 * them. */
static void test_owen_scramble(void)
{
    PtrRng rng = ptr_rng_for_sample(3, 0, 0);
    int leaked = 0, not_permuted = 0, checked = 0;
    static unsigned char hit[1 << 10];
    for (int trial = 0; trial < 200; trial++) {
        uint32_t seed = (uint32_t)ptr_rng_next(&rng);
        for (int k = 1; k <= 10; k++, checked++) {
            uint32_t low = (1u << k) - 1;
            memset(hit, 0, sizeof hit);
            for (uint32_t x = 0; x <= low; x++) {
                uint32_t high = (uint32_t)ptr_rng_next(&rng) & ~low;
                uint32_t a = ptr_laine_karras(x, seed), b = ptr_laine_karras(x | high, seed);
                leaked += (a & low) != (b & low);
                hit[a & low] = 1;
            }
            for (uint32_t cell = 0; cell <= low; cell++)
                not_permuted += !hit[cell];
        }
    }
    CHECK_INT(checked, 200 * 10);
    CHECK_INT(leaked, 0);
    CHECK_INT(not_permuted, 0);
}

/* Each of seed, pixel, index and dimension changes both numbers; so does
 * the kind of sampler. */
static void test_inputs_matter(void)
{
    uint32_t a[2], c[2];
    PtrSampler s = ptr_sampler_for_sample(PTR_SAMPLER_SOBOL, 3, 1234, 17);
    ptr_sampler_2d_bits(&s, 5, a);
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
    const TestCase cases[] = {
        TEST_CASE(test_nets),
        TEST_CASE(test_unscrambled_sobol),
        TEST_CASE(test_owen_scramble),
        TEST_CASE(test_inputs_matter),
        TEST_CASE(test_pairs_differ),
        TEST_CASE(test_floats),
    };
    TEST_RUN(cases);
    return test_report();
}
