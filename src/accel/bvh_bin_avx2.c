/* bvh_bin_c's binning with a bin grown by one 256-bit maximum, where the
 * reference takes two 128-bit ones (BvhBins): binning is the largest part
 * of a build, and each prim's three bins' loads and stores were most of
 * it. Built for AVX2, without FMA: the reference's maxima on the same
 * values, and its addition of one to the count (and of -0 to the lanes it
 * leaves alone, which changes no float), so the same bits. */
#include <immintrin.h>

#include "accel/bvh_split.h"

PTR_DECL_BVH_BIN(bvh_bin_avx2)
{
    const __m128 base = _mm_setr_ps(c->bin_base[0], c->bin_base[1], c->bin_base[2], 0.0f);
    const __m128 scale = _mm_setr_ps(c->bin_scale[0], c->bin_scale[1], c->bin_scale[2], 0.0f);
    const __m128 last = _mm_set1_ps((float)(c->bins - 1));
    const __m256 one_more = _mm256_setr_ps(BVH_BIN_ONE_MORE);
    for (size_t i = 0; i < count; i++) {
        __m128 neg_lower, upper;
        bvh_bin_box(&prims[i], magnitude, &neg_lower, &upper);
        const __m256 box = _mm256_insertf128_ps(_mm256_castps128_ps256(neg_lower), upper, 1);
        int k[4];
        _mm_storeu_si128((__m128i *)k, bvh_bins4(_mm_loadu_ps(prims[i].centre), base, scale, last));
        for (int a = 0; a < 3; a++) {
            float *bin = bins->box[a][k[a]];
            _mm256_store_ps(bin, _mm256_add_ps(_mm256_max_ps(_mm256_load_ps(bin), box), one_more));
        }
    }
}
