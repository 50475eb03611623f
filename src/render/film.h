/* The film: what a render keeps of each pixel while samples arrive, and the
 * image it resolves to. */
#ifndef PTR_FILM_H
#define PTR_FILM_H

#include <stddef.h>

/* What ptr_render_samples (render.h) keeps of each pixel, in doubles: the sum of its
 * samples' radiance, the sum over its odd-numbered samples (adaptive
 * sampling's second half-buffer), how many samples it took, whether
 * adaptive sampling stopped it (1) or not (0), and how many of its samples
 * were covered (their camera ray hit a sphere), in all and among the odd
 * ones: the alpha of a transparent render. A render with passes
 * (settings.h) keeps after these the sums of its samples' albedo and
 * normal (path.h, PtrPathPass); one without keeps PTR_ACCUM_STRIDE doubles
 * a pixel, its film no larger for the passes it does not take. */
enum {
    PTR_ACCUM_SUM = 0, PTR_ACCUM_ODD = 3, PTR_ACCUM_COUNT = 6, PTR_ACCUM_STOPPED = 7,
    PTR_ACCUM_COVERED = 8, PTR_ACCUM_COVERED_ODD = 9,
    PTR_ACCUM_STRIDE = 10,
    PTR_ACCUM_ALBEDO = 10, PTR_ACCUM_NORMAL = 13,
    PTR_ACCUM_STRIDE_PASSES = 16,
};

/* The doubles a pixel of a film with passes (1) or without (0). */
static inline size_t ptr_accum_stride(int passes)
{
    return passes ? PTR_ACCUM_STRIDE_PASSES : PTR_ACCUM_STRIDE;
}

/* A zeroed accumulation buffer of pixels pixels of stride doubles, or NULL
 * if memory runs out; ptr_accum_free takes the same count and stride. */
double *ptr_accum_alloc(size_t pixels, size_t stride);
void ptr_accum_free(double *acc, size_t pixels, size_t stride);

/* The mean radiance of each of pixels accumulated pixels (stride doubles
 * each) into rgb (3 floats a pixel); if alpha is not NULL, the share of its
 * samples covered; if sample_counts is not NULL, how many samples each
 * took. */
void ptr_accum_resolve(const double *acc, size_t pixels, size_t stride, float *rgb, float *alpha,
                       float *sample_counts);

/* The mean albedo and normal (3 floats a pixel each) of pixels pixels of a
 * film with passes. */
void ptr_accum_resolve_passes(const double *acc, size_t pixels, float *albedo, float *normal);

#endif /* PTR_FILM_H */
