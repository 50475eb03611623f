#include "denoise/transfer.h"

#include <float.h>
#include <math.h>

/* OIDN's fit of PU2, normalised at 100 cd/m^2 (core/color.h). */
static const float PU_A = 1.41283765e+03f, PU_B = 1.64593172e+00f, PU_C = 4.31384981e-01f,
                   PU_D = -2.94139609e-03f, PU_E = 1.92653254e-01f, PU_F = 6.26026094e-03f,
                   PU_G = 9.98620152e-01f, PU_Y0 = 1.57945760e-06f, PU_Y1 = 3.22087631e-02f,
                   PU_X0 = 2.23151711e-03f, PU_X1 = 3.70974749e-01f;

/* The largest HDR value the network was trained for (half's largest). */
static const float Y_MAX = 65504.0f;

float ptr_pu_forward(float y)
{
    if (y <= PU_Y0)
        return PU_A * y;
    if (y <= PU_Y1)
        return PU_B * powf(y, PU_C) + PU_D;
    return PU_E * logf(y + PU_F) + PU_G;
}

float ptr_pu_inverse(float x)
{
    if (x <= PU_X0)
        return x / PU_A;
    if (x <= PU_X1)
        return powf((x - PU_D) / PU_B, 1.0f / PU_C);
    return expf((x - PU_G) / PU_E) - PU_F;
}

/* The sRGB curve's constants (core/color.h). */
static const float SRGB_A = 12.92f, SRGB_B = 1.055f, SRGB_C = 1.0f / 2.4f, SRGB_D = -0.055f,
                   SRGB_Y0 = 0.0031308f, SRGB_X0 = 0.04045f;

float ptr_srgb_forward(float y)
{
    return y <= SRGB_Y0 ? SRGB_A * y : SRGB_B * powf(y, SRGB_C) + SRGB_D;
}

float ptr_srgb_inverse(float x)
{
    return x <= SRGB_X0 ? x / SRGB_A : powf((x - SRGB_D) / SRGB_B, 1.0f / SRGB_C);
}

/* NaN to 0, then clamped to [lo, hi]. */
static float sanitize(float v, float lo, float hi)
{
    return isnan(v) ? 0.0f : v < lo ? lo : v > hi ? hi : v;
}

static double luminance(const float *c)
{
    double rgb[3];
    for (int k = 0; k < 3; k++)
        rgb[k] = sanitize(c[k], 0.0f, FLT_MAX);
    return 0.212671 * rgb[0] + 0.715160 * rgb[1] + 0.072169 * rgb[2];
}

float ptr_autoexposure(const float *color, size_t stride, size_t width, size_t height)
{
    size_t bins_y = (height + 15) / 16, bins_x = (width + 15) / 16;
    double log_sum = 0.0;
    size_t counted = 0;
    for (size_t by = 0; by < bins_y; by++)
        for (size_t bx = 0; bx < bins_x; bx++) {
            size_t y0 = by * height / bins_y, y1 = (by + 1) * height / bins_y;
            size_t x0 = bx * width / bins_x, x1 = (bx + 1) * width / bins_x;
            double sum = 0.0;
            for (size_t y = y0; y < y1; y++)
                for (size_t x = x0; x < x1; x++)
                    sum += luminance(color + (y * width + x) * stride);
            double mean = sum / (double)((y1 - y0) * (x1 - x0));
            if (mean > 1e-8) {
                log_sum += log2(mean);
                counted++;
            }
        }
    return counted ? (float)(0.18 / exp2(log_sum / (double)counted)) : 1.0f;
}

void ptr_transfer_init(PtrTransfer *t, float exposure)
{
    t->input_scale = exposure;
    t->output_scale = exposure != 0.0f ? 1.0f / exposure : 0.0f;
    t->rcp_norm = ptr_pu_forward(Y_MAX);
    t->norm = 1.0f / t->rcp_norm;
}

void ptr_transfer_input(const PtrTransfer *t, const float *color, const float *albedo,
                        const float *normal, float *dst)
{
    for (int k = 0; k < 3; k++) {
        dst[k] = ptr_pu_forward(sanitize(color[k] * t->input_scale, 0.0f, FLT_MAX)) * t->norm;
        dst[3 + k] = sanitize(albedo[k], 0.0f, 1.0f);
    }
    ptr_transfer_normal_input(normal, dst + 6);
}

void ptr_transfer_output(const PtrTransfer *t, const float *src, float *rgb)
{
    for (int k = 0; k < 3; k++)
        rgb[k] = ptr_pu_inverse(sanitize(src[k], 0.0f, FLT_MAX) * t->rcp_norm) * t->output_scale;
}

void ptr_transfer_albedo_input(const float *albedo, float *dst)
{
    for (int k = 0; k < 3; k++)
        dst[k] = ptr_srgb_forward(sanitize(albedo[k], 0.0f, 1.0f));
}

void ptr_transfer_albedo_output(const float *src, float *albedo)
{
    for (int k = 0; k < 3; k++) {
        float v = ptr_srgb_inverse(sanitize(src[k], 0.0f, FLT_MAX));
        albedo[k] = v < 1.0f ? v : 1.0f;
    }
}

void ptr_transfer_normal_input(const float *normal, float *dst)
{
    for (int k = 0; k < 3; k++)
        dst[k] = sanitize(normal[k], -1.0f, 1.0f) * 0.5f + 0.5f;
}

void ptr_transfer_normal_output(const float *src, float *normal)
{
    for (int k = 0; k < 3; k++)
        normal[k] = sanitize(sanitize(src[k], 0.0f, FLT_MAX) * 2.0f - 1.0f, -1.0f, 1.0f);
}
