/* The numbers a camera sample's path consumes, as a pure function of (seed,
 * pixel, sample index, dimension): no state carries from one number to the
 * next, so any subset of sample indices renders on its own the very samples
 * of the whole render, whatever the threads, passes, sample ranges or
 * regions.
 *
 * Numbers come in pairs. A path asks for pair PTR_DIM_PIXEL, PTR_DIM_LENS,
 * then ptr_bounce_dim(bounce, slot): every bounce owns PTR_BOUNCE_SLOTS pairs
 * whether it uses them or not (padding), so a path that stops early or takes
 * another branch never shifts the dimensions of the next bounce. */
#ifndef PTR_SAMPLER_H
#define PTR_SAMPLER_H

#include <stdint.h>

#include "base/result.h"
#include "sampling/rng.h"

typedef enum PtrSamplerKind {
    /* Owen-scrambled Sobol' (0,2)-sequence, one independently scrambled and
     * shuffled copy per pair (Burley 2020, "Practical Hash-based Owen
     * Scrambling", JCGT 9(4)): the first 2^k samples of a pixel are a
     * (0,k,2)-net in every pair. */
    PTR_SAMPLER_SOBOL,
    /* Independent uniform numbers. */
    PTR_SAMPLER_INDEPENDENT,
} PtrSamplerKind;

/* Where a bounce's numbers go. */
enum {
    PTR_DIM_PIXEL = 0,       /* position inside the pixel */
    PTR_DIM_LENS = 1,        /* point on the lens */
    PTR_DIM_FIRST_BOUNCE = 2,
    PTR_SLOT_BSDF = 0,       /* the scattered direction */
    PTR_SLOT_BSDF_EXTRA = 1, /* Fresnel choice or fuzz radius (one of the pair) */
    PTR_SLOT_LIGHT_POINT = 2,/* the point on the chosen emitter */
    PTR_SLOT_LIGHT_PICK = 3, /* which emitter (alias table column, coin) */
    PTR_BOUNCE_SLOTS = 4,
};

typedef struct PtrSampler {
    PtrSamplerKind kind;
    uint64_t pixel_key; /* from seed and pixel */
    uint32_t index;     /* the sample index */
} PtrSampler;

static inline uint32_t ptr_bounce_dim(int bounce, int slot)
{
    return PTR_DIM_FIRST_BOUNCE + (uint32_t)bounce * PTR_BOUNCE_SLOTS + (uint32_t)slot;
}

PtrSampler ptr_sampler_for_sample(PtrSamplerKind kind, uint64_t seed, uint64_t pixel,
                                  uint32_t index);

static inline uint32_t ptr_reverse_bits(uint32_t x)
{
    x = (x >> 16) | (x << 16);
    x = ((x & 0x00ff00ffu) << 8) | ((x & 0xff00ff00u) >> 8);
    x = ((x & 0x0f0f0f0fu) << 4) | ((x & 0xf0f0f0f0u) >> 4);
    x = ((x & 0x33333333u) << 2) | ((x & 0xccccccccu) >> 2);
    x = ((x & 0x55555555u) << 1) | ((x & 0xaaaaaaaau) >> 1);
    return x;
}

/* Burley's improved Laine-Karras hash: a bijection in which each bit flips
 * depending only on the bits below it. Applied to a bit-reversed fraction it
 * is a nested uniform (Owen) scramble of it: every bit flips as a hash of
 * the bits above it decides. */
static inline uint32_t ptr_laine_karras(uint32_t x, uint32_t seed)
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
static inline uint32_t ptr_sobol_second_reversed(uint32_t index)
{
    index ^= (index >> 1) & 0x55555555u;
    index ^= (index >> 2) & 0x33333333u;
    index ^= (index >> 4) & 0x0f0f0f0fu;
    index ^= (index >> 8) & 0x00ff00ffu;
    index ^= (index >> 16) & 0x0000ffffu;
    return index;
}

/* The key of pair dim of the pixel keyed pixel_key, from which its
 * numbers are drawn. */
static inline uint64_t ptr_sampler_pair_key(uint64_t pixel_key, uint32_t dim)
{
    return ptr_mix64(pixel_key ^ ((uint64_t)(dim + 1) * UINT64_C(0xd1b54a32d192ed03)));
}

/* PTR_SAMPLER_INDEPENDENT's pair for sample index, from its pair's key. */
static inline void ptr_independent_pair_bits(uint64_t pair_key, uint32_t index, uint32_t out[2])
{
    uint64_t h = ptr_mix64(pair_key ^ ((uint64_t)index * UINT64_C(0x9e3779b97f4a7c15)));
    out[0] = (uint32_t)(h >> 32);
    out[1] = (uint32_t)h;
}

/* PTR_SAMPLER_SOBOL's pair for sample index, as 32-bit fractions, from the
 * seed of the index's shuffle (the low half of the pair's key) and the two
 * scrambles (ptr_mix64 of the whole key). 32-bit arithmetic only, so that
 * bundles of paths compute it for eight lanes in one vector register, having
 * made the 64-bit keys before it in wider ones. */
static inline void ptr_sobol_pair_bits(uint32_t shuffle_seed, uint64_t scramble, uint32_t index,
                                       uint32_t out[2])
{
    /* The shuffle, an Owen scramble of the index, maps every aligned block
     * of 2^k indices onto another aligned block (bits flip as the bits above
     * them decide), and any such block of a (0,2)-sequence is a (0,k,2)-net;
     * it decorrelates this pair from the others (padding). */
    uint32_t i = ptr_reverse_bits(ptr_laine_karras(ptr_reverse_bits(index), shuffle_seed));
    out[0] = ptr_reverse_bits(ptr_laine_karras(i, (uint32_t)scramble));
    out[1] = ptr_reverse_bits(
        ptr_laine_karras(ptr_sobol_second_reversed(i), (uint32_t)(scramble >> 32)));
}

/* The pair of numbers for pair dim of sample index of the pixel keyed
 * pixel_key, as 32-bit fractions. */
static inline void ptr_sampler_pair_bits(PtrSamplerKind kind, uint64_t pixel_key, uint32_t index,
                                         uint32_t dim, uint32_t out[2])
{
    const uint64_t pair_key = ptr_sampler_pair_key(pixel_key, dim);
    if (kind == PTR_SAMPLER_INDEPENDENT)
        ptr_independent_pair_bits(pair_key, index, out);
    else
        ptr_sobol_pair_bits((uint32_t)pair_key, ptr_mix64(pair_key), index, out);
}

/* A 32-bit fraction as a float in [0, 1) with 24 bits, exact. */
static inline float ptr_sample_float(uint32_t bits)
{
    return (float)(int32_t)(bits >> 8) * 0x1.0p-24f;
}

/* Two numbers in [0, 1) with 24 bits each (exact in a float) for pair dim. */
static inline void ptr_sampler_2d(const PtrSampler *sampler, uint32_t dim, float out[2])
{
    uint32_t bits[2];
    ptr_sampler_pair_bits(sampler->kind, sampler->pixel_key, sampler->index, dim, bits);
    out[0] = ptr_sample_float(bits[0]);
    out[1] = ptr_sample_float(bits[1]);
}

/* The same pair as 32-bit fractions, for choices among many. */
static inline void ptr_sampler_2d_bits(const PtrSampler *sampler, uint32_t dim, uint32_t out[2])
{
    ptr_sampler_pair_bits(sampler->kind, sampler->pixel_key, sampler->index, dim, out);
}

/* "sobol" or "independent"; PTR_ERR_USAGE for anything else. */
PtrResult ptr_sampler_parse(const char *text, PtrSamplerKind *kind, PtrError *err);
const char *ptr_sampler_name(PtrSamplerKind kind);

#endif /* PTR_SAMPLER_H */
