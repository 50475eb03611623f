/* The film of a render (ptr_accum_stride doubles a pixel): where it lives,
 * and what it resolves to. */
#define _DEFAULT_SOURCE /* MAP_ANONYMOUS, madvise */
#include "render/film.h"

#include <stdint.h>
#include <sys/mman.h>

/* The render threads touch the buffer first, page by page, and each first
 * touch is a page fault; faults from two threads at once contend in the
 * kernel. On seed.gltf at 20 samples on 2 threads they cost 0.1 s of system
 * time, a fifth of the wall time; transparent huge pages (2 MB) make them
 * 512 times fewer (10,500 page faults in all down to 2,600, system time
 * 0.01 s). The buffer is whole huge pages, mapped apart from the heap. */
enum { HUGE_PAGE = 2 << 20 };

static size_t accum_bytes(size_t pixels, size_t stride)
{
    size_t bytes = (pixels ? pixels : 1) * stride * sizeof(double);
    return (bytes + HUGE_PAGE - 1) / HUGE_PAGE * HUGE_PAGE;
}

double *ptr_accum_alloc(size_t pixels, size_t stride)
{
    if (pixels > SIZE_MAX / 2 / (stride * sizeof(double)))
        return NULL;
    size_t bytes = accum_bytes(pixels, stride);
    void *acc = mmap(NULL, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (acc == MAP_FAILED)
        return NULL;
#ifdef MADV_HUGEPAGE
    madvise(acc, bytes, MADV_HUGEPAGE); /* a hint: without it, small pages */
#endif
    return acc; /* anonymous pages read as zero */
}

void ptr_accum_free(double *acc, size_t pixels, size_t stride)
{
    if (acc)
        munmap(acc, accum_bytes(pixels, stride));
}

void ptr_accum_resolve(const double *acc, size_t pixels, size_t stride, float *rgb, float *alpha,
                       float *sample_counts)
{
    for (size_t p = 0; p < pixels; p++, acc += stride) {
        double n = acc[PTR_ACCUM_COUNT];
        for (int c = 0; c < 3; c++)
            rgb[3 * p + c] = n > 0 ? (float)(acc[PTR_ACCUM_SUM + c] / n) : 0.0f;
        if (alpha)
            alpha[p] = n > 0 ? (float)(acc[PTR_ACCUM_COVERED] / n) : 0.0f;
        if (sample_counts)
            sample_counts[p] = (float)n;
    }
}

void ptr_accum_resolve_passes(const double *acc, size_t pixels, float *albedo, float *normal)
{
    for (size_t p = 0; p < pixels; p++, acc += PTR_ACCUM_STRIDE_PASSES) {
        double n = acc[PTR_ACCUM_COUNT];
        for (int c = 0; c < 3; c++) {
            albedo[3 * p + c] = n > 0 ? (float)(acc[PTR_ACCUM_ALBEDO + c] / n) : 0.0f;
            normal[3 * p + c] = n > 0 ? (float)(acc[PTR_ACCUM_NORMAL + c] / n) : 0.0f;
        }
    }
}
