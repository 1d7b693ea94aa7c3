/* Brigade's adaptive convergence (Bikker & van Schijndel 2013, section 4.7; core/convergence.h picks f from
 * the camera's motion): the accumulated image C = (1 - f) C_prev + f C_new, one value at a time, written once
 * for the host's threads (core::AdaptiveConvergence, whose blend HostFramePost runs too) and a GPU's post
 * (CudaFramePost). */
#ifndef COHORT_KERNEL_BRIGADE_BLEND_H
#define COHORT_KERNEL_BRIGADE_BLEND_H
#include "portable.h"

KFN float k_brigade_blend(float previous, float fresh, float f) { return previous + f * (fresh - previous); }

/* Pixel p of an RGBA plane. */
KFN void k_brigade_blend_pixel(KGLOBAL float* accumulated, KGLOBAL const float* fresh, float f, kint p) {
  for (int k = 0; k < 4; ++k) accumulated[4 * p + k] = k_brigade_blend(accumulated[4 * p + k], fresh[4 * p + k], f);
}

#endif
