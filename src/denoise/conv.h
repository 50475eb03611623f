/* The denoiser's 3x3 convolutions: the one operation that costs, behind a
 * kernel table filled from the dispatch ladder like the intersectors'.
 *
 * Feature maps are held pixel by pixel (HWC), each pixel's channels
 * contiguous and padded with zeros to a multiple of PTR_CONV_BLOCK, with a
 * border of one pixel of zeros all round: rows of width + 2 pixels, height + 2
 * rows. The border is the convolution's zero padding, so no kernel tests an
 * edge.
 *
 * Every version computes each output value with the same operations in the
 * same order as the C reference, one fused multiply-add a term:
 *
 *     acc = bias[o]
 *     for ky in 0..2, kx in 0..2, i in 0..in_channels-1:
 *         acc = fmaf(in[y + ky - 1][x + kx - 1][i], w[o][i][ky][kx], acc)
 *     out[y][x][o] = relu ? (acc > 0 ? acc : 0) : acc
 *
 * so that a denoised image is the same, bit for bit, at every CPU level and
 * with any number of threads. */
#ifndef PTR_CONV_H
#define PTR_CONV_H

#include <stddef.h>

#include "base/cpu.h"

/* Channels come in blocks of 16: one AVX-512 register, two AVX2 ones. */
enum { PTR_CONV_BLOCK = 16 };

/* Packed weights: for each block of 16 output channels, for each tap
 * (ky, kx, row-major), for each input channel, that block's 16 weights;
 * 64-byte aligned. ptr_conv_pack makes them from a tensor in OIHW order. */
static inline size_t ptr_conv_weight_index(size_t o, size_t i, size_t tap, size_t in_channels)
{
    return ((o / PTR_CONV_BLOCK * 9 + tap) * in_channels + i) * PTR_CONV_BLOCK +
           o % PTR_CONV_BLOCK;
}

/* Computes rows output rows of width pixels and out_channels channels.
 *   dst: the output's first pixel to write (its row y0, column 0, inside
 *        the border): rows of (width + 2) * out_channels floats;
 *   src: the input's padded row y0 - 1 at its border column: rows of
 *        (width + 2) * in_channels floats; rows + 2 rows are read;
 *   weights: packed as above; bias: out_channels floats.
 * in_channels and out_channels are multiples of PTR_CONV_BLOCK; dst, src
 * and weights are 64-byte aligned; width >= 1. The border of dst is not
 * written. */
#define PTR_DECL_CONV3X3(name)                                                \
    void name(float *dst, const float *src, const float *weights,             \
              const float *bias, size_t width, size_t rows,                   \
              size_t in_channels, size_t out_channels, int relu)

typedef PTR_DECL_CONV3X3((*PtrConv3x3Fn));

typedef struct PtrConvTable {
    PtrConv3x3Fn conv3x3;
    const char *name; /* "c", "avx2", "avx512" */
} PtrConvTable;

/* Fills the table as a CPU of this level would: the C reference, then each
 * level's assembly up to it. */
void ptr_conv_init_level(PtrConvTable *table, PtrCpuLevel level);

PTR_DECL_CONV3X3(ptr_conv3x3_c);

/* Packs a convolution's weights given in OIHW order (out x in x 3 x 3) into
 * packed (64-byte aligned, zero-padded to padded_in x padded_out channels),
 * which holds ptr_conv_weight_count(padded_in, padded_out) floats. */
static inline size_t ptr_conv_weight_count(size_t padded_in, size_t padded_out)
{
    return padded_out * 9 * padded_in;
}
void ptr_conv_pack(float *packed, const float *oihw, size_t in, size_t out,
                   size_t padded_in, size_t padded_out);

#endif /* PTR_CONV_H */
