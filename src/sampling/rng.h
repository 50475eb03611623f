/* Counter-based random numbers. Every camera sample owns a stream keyed by
 * (seed, pixel, sample index), so an image does not depend on how pixels are
 * shared out among threads, and any subset of sample indices can be rendered
 * on its own and still be the very samples of the whole render. */
#ifndef PTR_RNG_H
#define PTR_RNG_H

#include <stdint.h>

typedef struct PtrRng {
    uint64_t state;
} PtrRng;

/* SplitMix64's output function: a bijective 64-bit mixer with full avalanche. */
static inline uint64_t ptr_mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * UINT64_C(0xbf58476d1ce4e5b9);
    z = (z ^ (z >> 27)) * UINT64_C(0x94d049bb133111eb);
    return z ^ (z >> 31);
}

static inline PtrRng ptr_rng_for_sample(uint64_t seed, uint64_t pixel, uint64_t sample)
{
    uint64_t key = ptr_mix64(seed + UINT64_C(0x9e3779b97f4a7c15));
    key = ptr_mix64(key ^ pixel);
    key = ptr_mix64(key ^ (sample * UINT64_C(0xd1b54a32d192ed03)));
    return (PtrRng){ key };
}

static inline uint64_t ptr_rng_next(PtrRng *rng)
{
    rng->state += UINT64_C(0x9e3779b97f4a7c15);
    return ptr_mix64(rng->state);
}

/* Uniform in [0, 1), with 24 random bits: every value is exact in a float. */
static inline float ptr_rng_float(PtrRng *rng)
{
    return (float)(ptr_rng_next(rng) >> 40) * 0x1.0p-24f;
}

#endif /* PTR_RNG_H */
