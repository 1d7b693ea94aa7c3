/* The variance-guided a-trous filter of SVGF (Schied et al., "Spatiotemporal Variance-Guided Filtering",
 * HPG 2017), one pixel at a time, over the illumination (kernel/illumination.h). Two steps a frame:
 *
 *   k_svgf_variance_pixel  each pixel's luminance variance: M2 - M1^2 from the temporal moments the
 *                          reprojected history keeps (kernel/reproject.h), or, where that history is
 *                          shorter than `short_history` frames (or there is none), from the moments of the
 *                          7x7 neighbourhood on the same surface (normal and depth stops), boosted by
 *                          short_history / length as SVGF does, since few frames underestimate it;
 *                          with of_mean, either is divided by the history length: the variance of the
 *                          accumulated mean the filter sees rather than of one frame's sample;
 *   k_svgf_atrous_pixel    one a-trous pass (kernel/atrous.h's taps, spline and geometric stops) whose
 *                          luminance stop is |l_p - l_q| / (sigma * sqrt(g3x3(var_p)) + eps): the
 *                          difference in standard deviations of the pixel's own noise, so converged pixels
 *                          are left alone and noisy ones are smoothed hard. The variance is filtered along
 *                          with the colour (weights squared: the variance of the weighted mean), so later
 *                          passes see the noise that is left.
 *
 * Planes: illumination RGBA floats (the passes keep the variance in alpha), moments two floats a pixel,
 * history length one; normal and depth packed (k_atrous_pack_geometry) for the estimate and the passes:
 * one 16-byte load a tap, where the 7x7 estimate's four loads a tap set its cost on GPUs. */
#ifndef COHORT_KERNEL_SVGF_H
#define COHORT_KERNEL_SVGF_H
#include "atrous.h"

typedef struct KSvgfVarianceParams {
  kint width; kint height; kint normal_squarings;
  kint have_history;    /* 0: no temporal moments (no reprojection): always the spatial estimate */
  float depth_sigma;    /* relative depth difference per pixel of tap distance (the a-trous filter's) */
  float short_history;  /* frames: a history shorter than this gets the spatial estimate (SVGF: 4) */
  kint of_mean;         /* 1: the variance of the accumulated mean (the samples' over the history length),
                           not SVGF's variance of one frame's sample */
  float pad1;
} KSvgfVarianceParams;

/* Added to the luminance stop's scale: pixels with no measured noise still mix with equal neighbours. */
#define K_SVGF_LUMINANCE_EPSILON 1e-4f
#define K_SVGF_SPATIAL_RADIUS 3

/* The pixel's variance. `illumination` is the demodulated frame the passes filter (only its RGB is read);
 * moments and length are the reprojected history's (read only with have_history). */
KFN float k_svgf_variance_estimate(KGLOBAL const float* illumination, KGLOBAL const float* moments,
                                   KGLOBAL const float* length, KGLOBAL const float* geometry,
                                   const KSvgfVarianceParams* p, kint x, kint y) {
  kint centre = y * p->width + x;
  float history = p->have_history ? length[centre] : 0.0f;
  float of_mean = p->of_mean ? 1.0f / k_fmax(history, 1.0f) : 1.0f;
  if (history >= p->short_history)
    return k_fmax(moments[2 * centre + 1] - moments[2 * centre] * moments[2 * centre], 0.0f) * of_mean;
  KFloat4 gp = k_load4(geometry + 4 * centre);
  float zp = gp.w;
  KVec3 np = v3(gp.x, gp.y, gp.z);
  float inv_depth_scale = k_atrous_inv_depth_scale(p->depth_sigma, zp, 1);
  float s1 = 0.0f, s2 = 0.0f, weight_sum = 0.0f;
  for (kint dy = -K_SVGF_SPATIAL_RADIUS; dy <= K_SVGF_SPATIAL_RADIUS; ++dy) {
    kint qy = y + dy;
    if (qy < 0 || qy >= p->height) continue;
    for (kint dx = -K_SVGF_SPATIAL_RADIUS; dx <= K_SVGF_SPATIAL_RADIUS; ++dx) {
      kint qx = x + dx;
      if (qx < 0 || qx >= p->width) continue;
      kint q = qy * p->width + qx;
      float m1, m2;
      if (p->have_history && length[q] > 0.0f) {
        m1 = moments[2 * q];
        m2 = moments[2 * q + 1];
      } else {
        KGLOBAL const float* c = illumination + 4 * q;
        if (!k_finite3(c[0], c[1], c[2])) continue;
        m1 = k_atrous_luminance(c);
        m2 = m1 * m1;
      }
      if (!(k_fabs(m1) < 1e18f) || !(m2 < 3e38f)) continue;
      float w = 1.0f;
      if (q != centre) {
        float exponent = 0.0f;
        KFloat4 gq = k_load4(geometry + 4 * q);
        w = k_atrous_geometry_stop(zp, np, gq.w, v3(gq.x, gq.y, gq.z), inv_depth_scale, p->normal_squarings,
                                   &exponent);
        if (!(w > 0.0f)) continue;
        kint ax = dx < 0 ? -dx : dx, ay = dy < 0 ? -dy : dy;
        exponent /= (float)(ax > ay ? ax : ay); /* relative depth per pixel of (Chebyshev) distance */
        if (exponent > 12.0f) continue;
        w *= k_exp(-exponent);
      }
      s1 += w * m1;
      s2 += w * m2;
      weight_sum += w;
    }
  }
  float v = 0.0f;
  if (weight_sum > 0.0f) {
    float mean = s1 / weight_sum;
    v = k_fmax(s2 / weight_sum - mean * mean, 0.0f);
  }
  return v * (p->short_history / k_fmax(history, 1.0f)) * of_mean;
}

/* The estimate into a plane of one float a pixel. */
KFN void k_svgf_variance_pixel(KGLOBAL const float* illumination, KGLOBAL const float* moments,
                               KGLOBAL const float* length, KGLOBAL const float* geometry, KGLOBAL float* variance,
                               const KSvgfVarianceParams* p, kint x, kint y) {
  variance[y * p->width + x] = k_svgf_variance_estimate(illumination, moments, length, geometry, p, x, y);
}

/* The pixel's variance (the alpha of the passes' RGBA planes) seen through a 3x3 Gaussian (1/4 centre, 1/8
 * sides, 1/16 corners; SVGF), which steadies the luminance stop against the estimate's own noise. */
KFN float k_svgf_blurred_variance(KGLOBAL const float* rgba_variance, const KAtrousParams* p, kint x, kint y) {
  const float gauss[2] = {0.25f, 0.125f};
  float sum = 0.0f, weight_sum = 0.0f;
  for (kint dy = -1; dy <= 1; ++dy) {
    kint qy = y + dy;
    if (qy < 0 || qy >= p->height) continue;
    for (kint dx = -1; dx <= 1; ++dx) {
      kint qx = x + dx;
      if (qx < 0 || qx >= p->width) continue;
      float w = gauss[dx != 0] * gauss[dy != 0] * 4.0f;
      sum += w * rgba_variance[4 * (qy * p->width + qx) + 3];
      weight_sum += w;
    }
  }
  return sum / weight_sum;
}

/* One pass over illumination planes whose alpha holds the variance (k_atrous_pass_pixel, guided);
 * p->color_sigma is the luminance stop in standard deviations (SVGF: 4). */
KFN void k_svgf_atrous_pixel(KGLOBAL const float* in_rgba, KGLOBAL float* out_rgba, KGLOBAL const float* geometry,
                             const KAtrousParams* p, kint x, kint y) {
  float inv_luminance_scale =
      1.0f / (p->color_sigma * k_sqrt(k_fmax(k_svgf_blurred_variance(in_rgba, p, x, y), 0.0f)) +
              K_SVGF_LUMINANCE_EPSILON);
  k_atrous_pass_pixel(in_rgba, out_rgba, geometry, p, 1, inv_luminance_scale, x, y);
}

#endif
