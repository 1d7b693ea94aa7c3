/* Illumination: a colour divided by its surface's albedo, which the real-time denoiser filters (so
 * textures stay sharp) and whose luminance moments the temporal history keeps (kernel/reproject.h,
 * kernel/svgf.h). One definition, so the history's variance and the filter's luminance agree. */
#ifndef COHORT_KERNEL_ILLUMINATION_H
#define COHORT_KERNEL_ILLUMINATION_H
#include "vec.h"

/* Black surfaces divide by the least albedo and multiply back by the same. */
#define K_ILLUMINATION_LEAST_ALBEDO 0.01f

KFN float k_luminance3(float r, float g, float b) { return 0.2126f * r + 0.7152f * g + 0.0722f * b; }

/* The luminance of pixel p's illumination: its RGBA colour over its RGB albedo. */
KFN float k_illumination_luminance(KGLOBAL const float* rgba, KGLOBAL const float* albedo, kint p) {
  return k_luminance3(rgba[4 * p] / k_fmax(albedo[3 * p], K_ILLUMINATION_LEAST_ALBEDO),
                      rgba[4 * p + 1] / k_fmax(albedo[3 * p + 1], K_ILLUMINATION_LEAST_ALBEDO),
                      rgba[4 * p + 2] / k_fmax(albedo[3 * p + 2], K_ILLUMINATION_LEAST_ALBEDO));
}

#endif
