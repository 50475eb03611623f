#include "sampling/sampler.h"

#include <string.h>

PtrSampler ptr_sampler_for_sample(PtrSamplerKind kind, uint64_t seed, uint64_t pixel,
                                  uint32_t index)
{
    uint64_t key = ptr_mix64(seed + UINT64_C(0x9e3779b97f4a7c15));
    return (PtrSampler){ kind, ptr_mix64(key ^ pixel), index };
}

static const char *const names[] = { [PTR_SAMPLER_SOBOL] = "sobol",
                                     [PTR_SAMPLER_INDEPENDENT] = "independent" };

PtrResult ptr_sampler_parse(const char *text, PtrSamplerKind *kind, PtrError *err)
{
    for (int k = PTR_SAMPLER_SOBOL; k <= PTR_SAMPLER_INDEPENDENT; k++)
        if (!strcmp(text, names[k])) {
            *kind = (PtrSamplerKind)k;
            return PTR_OK;
        }
    return ptr_error_set(err, PTR_ERR_USAGE, "'%s' is not sobol or independent", text);
}

const char *ptr_sampler_name(PtrSamplerKind kind)
{
    return names[kind];
}
