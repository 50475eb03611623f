/* Sine and cosine of an angle given in turns, ptr's own: the path tracer's
 * scalar reference and its bundles of paths (render/bundle.c, compiled for
 * several instruction sets) must compute the same bits, which a library's
 * sinf may not promise across calls, inlining and vectorisation. Every angle
 * ptr takes is 2 pi times a uniform number in [0, 1), so the argument comes
 * in turns: the reduction to an octant is exact (u * 4 - k), and no digits
 * are lost to a multiple of pi. */
#ifndef PTR_TRIG_H
#define PTR_TRIG_H

#include "base/vec.h"

/* sin and cos of 2 pi u for u in [0, 1), within 2e-7 absolutely (tested
 * against double precision in tests/unit/test_trig.c). Branch-free, so loops
 * over lanes vectorise. */
static inline void ptr_sincos_turns(float u, float *sin_out, float *cos_out)
{
    /* u = (k + f) / 4 with k the nearest quarter turn, f in [-1/2, 1/2]. */
    float quarters = u * 4.0f;
    int k = (int)(quarters + 0.5f);
    float x = (quarters - (float)k) * (0.5f * PTR_PI); /* in [-pi/4, pi/4] */
    float x2 = x * x;
    /* Minimax polynomials on [-pi/4, pi/4] (Cephes' sinf and cosf). */
    const float s1 = -1.6666654611e-1f, s2 = 8.3321608736e-3f, s3 = -1.9515295891e-4f;
    const float c1 = 4.166664568298827e-2f, c2 = -1.388731625493765e-3f, c3 = 2.443315711809948e-5f;
    float s = x + x * x2 * (s1 + x2 * (s2 + x2 * s3));
    float c = 1.0f - 0.5f * x2 + x2 * x2 * (c1 + x2 * (c2 + x2 * c3));
    /* Turning by k quarters: odd k swaps sine and cosine, and the signs
     * follow the quadrant. */
    float s_k = (k & 1) ? c : s, c_k = (k & 1) ? s : c;
    *sin_out = (k & 2) ? -s_k : s_k;
    *cos_out = ((k + 1) & 2) ? -c_k : c_k;
}

#endif /* PTR_TRIG_H */
