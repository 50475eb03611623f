/* Open Image Denoise's processing of HDR colour around its network: the
 * exposure that brings the image's mean to mid-grey, the perceptually
 * uniform (PU) transfer function that maps light to the network's input
 * range, and its inverse on the way out (docs/denoise.md). */
#ifndef PTR_TRANSFER_H
#define PTR_TRANSFER_H

#include <stddef.h>

/* The PU curve (Aydin et al. 2008, as OIDN fits it), unnormalised. */
float ptr_pu_forward(float y);
float ptr_pu_inverse(float x);

/* The sRGB curve, from linear and back. */
float ptr_srgb_forward(float y);
float ptr_srgb_inverse(float x);

/* 0.18 over the geometric mean of the luminance of the image's bins (at
 * most 16x16 pixels, as many as fit), counting bins brighter than 1e-8;
 * 1 if none is. color: pixel i at color + i * stride. */
float ptr_autoexposure(const float *color, size_t stride, size_t width, size_t height);

typedef struct PtrTransfer {
    float input_scale, output_scale; /* the exposure and its inverse */
    float norm, rcp_norm;            /* PU(65504) maps to 1 */
} PtrTransfer;

void ptr_transfer_init(PtrTransfer *t, float exposure);

/* One pixel of the network's input: colour, albedo, normal (each RGB) to
 * the 9 values at dst, each sanitised as OIDN does (NaN to 0; colour
 * non-negative, albedo in [0, 1], normal in [-1, 1] then mapped to [0, 1]). */
void ptr_transfer_input(const PtrTransfer *t, const float *color, const float *albedo,
                        const float *normal, float *dst);

/* One pixel of the network's output (3 values) back to linear RGB. */
void ptr_transfer_output(const PtrTransfer *t, const float *src, float *rgb);

/* The networks that filter a guide alone (OIDN's rt_alb, rt_nrm): albedo
 * goes in through the sRGB curve, clamped to [0, 1], and comes out clamped
 * to [0, 1]; a normal goes in mapped from [-1, 1] to [0, 1] and comes out
 * mapped back. Each from 3 values to 3. */
void ptr_transfer_albedo_input(const float *albedo, float *dst);
void ptr_transfer_albedo_output(const float *src, float *albedo);
void ptr_transfer_normal_input(const float *normal, float *dst);
void ptr_transfer_normal_output(const float *src, float *normal);

#endif /* PTR_TRANSFER_H */
