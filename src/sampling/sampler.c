#include "sampling/sampler.h"

#include <string.h>

#include "sampling/rng.h"

static uint32_t reverse_bits(uint32_t x)
{
    x = __builtin_bswap32(x);
    x = ((x & 0x0f0f0f0fu) << 4) | ((x & 0xf0f0f0f0u) >> 4);
    x = ((x & 0x33333333u) << 2) | ((x & 0xccccccccu) >> 2);
    x = ((x & 0x55555555u) << 1) | ((x & 0xaaaaaaaau) >> 1);
    return x;
}

/* Burley's improved Laine-Karras hash: a bijection in which each bit flips
 * depending only on the bits below it. Applied to a bit-reversed fraction it
 * is a nested uniform (Owen) scramble of it: every bit flips as a hash of
 * the bits above it decides. */
static uint32_t laine_karras(uint32_t x, uint32_t seed)
{
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return x;
}

/* The second Sobol' dimension (primitive polynomial x + 1, m1 = 1), bit
 * reversed: its direction numbers v(k+1) = v(k) xor v(k) / 2 from v(1) = 1/2
 * are the rows of Pascal's triangle mod 2, so by Lucas' theorem bit j of
 * direction number k is set when j's bits are a subset of k's. The sum over
 * the index's bits is then a superset-sum transform over the 5-bit bit
 * positions, five butterfly steps. (The first dimension, van der Corput, is
 * the reversed index itself; the two form a (0,2)-sequence in base 2.) */
static uint32_t sobol_second_reversed(uint32_t index)
{
    index ^= (index >> 1) & 0x55555555u;
    index ^= (index >> 2) & 0x33333333u;
    index ^= (index >> 4) & 0x0f0f0f0fu;
    index ^= (index >> 8) & 0x00ff00ffu;
    index ^= (index >> 16) & 0x0000ffffu;
    return index;
}

PtrSampler ptr_sampler_for_sample(PtrSamplerKind kind, uint64_t seed, uint64_t pixel,
                                  uint32_t index)
{
    uint64_t key = ptr_mix64(seed + UINT64_C(0x9e3779b97f4a7c15));
    return (PtrSampler){ kind, ptr_mix64(key ^ pixel), index };
}

void ptr_sampler_2d_bits(const PtrSampler *s, uint32_t dim, uint32_t out[2])
{
    uint64_t pair_key = ptr_mix64(s->pixel_key ^ ((uint64_t)(dim + 1) * UINT64_C(0xd1b54a32d192ed03)));
    if (s->kind == PTR_SAMPLER_INDEPENDENT) {
        uint64_t h = ptr_mix64(pair_key ^ ((uint64_t)s->index * UINT64_C(0x9e3779b97f4a7c15)));
        out[0] = (uint32_t)(h >> 32);
        out[1] = (uint32_t)h;
        return;
    }
    /* The shuffle, an Owen scramble of the index, maps every aligned block
     * of 2^k indices onto another aligned block (bits flip as the bits above
     * them decide), and any such block of a (0,2)-sequence is a (0,k,2)-net;
     * it decorrelates this pair from the others (padding). */
    uint64_t scramble = ptr_mix64(pair_key);
    uint32_t i = reverse_bits(laine_karras(reverse_bits(s->index), (uint32_t)pair_key));
    out[0] = reverse_bits(laine_karras(i, (uint32_t)scramble));
    out[1] = reverse_bits(laine_karras(sobol_second_reversed(i), (uint32_t)(scramble >> 32)));
}

void ptr_sampler_2d(const PtrSampler *s, uint32_t dim, float out[2])
{
    uint32_t bits[2];
    ptr_sampler_2d_bits(s, dim, bits);
    out[0] = (float)(bits[0] >> 8) * 0x1.0p-24f;
    out[1] = (float)(bits[1] >> 8) * 0x1.0p-24f;
}

static const char *const names[] = { [PTR_SAMPLER_SOBOL] = "sobol",
                                     [PTR_SAMPLER_INDEPENDENT] = "independent" };

int ptr_sampler_parse(const char *text, PtrSamplerKind *kind)
{
    for (int k = PTR_SAMPLER_SOBOL; k <= PTR_SAMPLER_INDEPENDENT; k++)
        if (!strcmp(text, names[k])) {
            *kind = (PtrSamplerKind)k;
            return 1;
        }
    return 0;
}

const char *ptr_sampler_name(PtrSamplerKind kind)
{
    return names[kind];
}
