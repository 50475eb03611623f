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

/* Two numbers in [0, 1) with 24 bits each (exact in a float) for pair dim. */
void ptr_sampler_2d(const PtrSampler *sampler, uint32_t dim, float out[2]);

/* The same pair as 32-bit fractions, for choices among many. */
void ptr_sampler_2d_bits(const PtrSampler *sampler, uint32_t dim, uint32_t out[2]);

/* "sobol" or "independent". */
int ptr_sampler_parse(const char *text, PtrSamplerKind *kind);
const char *ptr_sampler_name(PtrSamplerKind kind);

#endif /* PTR_SAMPLER_H */
