#include "denoise/conv.h"

#include <math.h>

#ifndef PTR_HAVE_ASM
#define PTR_HAVE_ASM 0
#endif

#if PTR_HAVE_ASM
PTR_DECL_CONV3X3(ptr_conv3x3_avx2);
PTR_DECL_CONV3X3(ptr_conv3x3_avx512);
#endif

PTR_DECL_CONV3X3(ptr_conv3x3_c)
{
    size_t src_row = (width + 2) * in_channels;
    size_t dst_row = (width + 2) * out_channels;
    for (size_t y = 0; y < rows; y++) {
        for (size_t x = 0; x < width; x++) {
            float *out = dst + y * dst_row + x * out_channels;
            for (size_t o = 0; o < out_channels; o++) {
                float acc = bias[o];
                for (size_t tap = 0; tap < 9; tap++) {
                    const float *in = src + (y + tap / 3) * src_row + (x + tap % 3) * in_channels;
                    const float *w = weights + ptr_conv_weight_index(o, 0, tap, in_channels);
                    for (size_t i = 0; i < in_channels; i++)
                        acc = fmaf(in[i], w[i * PTR_CONV_BLOCK], acc);
                }
                out[o] = relu && !(acc > 0.0f) ? 0.0f : acc;
            }
        }
    }
}

void ptr_conv_pack(float *packed, const float *oihw, size_t in, size_t out,
                   size_t padded_in, size_t padded_out)
{
    for (size_t o = 0; o < padded_out; o++)
        for (size_t tap = 0; tap < 9; tap++)
            for (size_t i = 0; i < padded_in; i++)
                packed[ptr_conv_weight_index(o, i, tap, padded_in)] =
                    o < out && i < in ? oihw[(o * in + i) * 9 + tap] : 0.0f;
}

void ptr_conv_init_level(PtrConvTable *table, PtrCpuLevel level)
{
    table->conv3x3 = ptr_conv3x3_c;
    table->name = "c";
#if PTR_HAVE_ASM
    /* SSE4.1 has no fused multiply-add: the reference's operations start at
     * AVX2 (which ptr's CPU detection grants only with FMA). */
    if (level < PTR_CPU_AVX2)
        return;
    table->conv3x3 = ptr_conv3x3_avx2;
    table->name = "avx2";
    if (level < PTR_CPU_AVX512)
        return;
    table->conv3x3 = ptr_conv3x3_avx512;
    table->name = "avx512";
#else
    (void)level;
#endif
}
