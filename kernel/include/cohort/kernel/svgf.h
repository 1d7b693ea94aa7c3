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
 *   k_svgf_history_fix_pixel  before the passes (ReLAX's and ReBLUR's HistoryFix, NVIDIA NRD): a pixel
 *                          whose history is shorter than `frames` gets a wider blur of its illumination, a
 *                          5x5 B3 spline whose taps lie `stride` pixels apart at a one-frame history and
 *                          closer together as the history grows, with the a-trous filter's normal stop, its depth
 *                          stop relative to the nearer depth (symmetric, and per pixel of distance), an
 *                          id stop (another entity is another surface) and a loose luminance stop (the
 *                          passes' times a scale: it keeps a lamp's light off the wall around it, while a
 *                          short history's noise passes); the variance in alpha follows the colour, weights
 *                          squared, so the passes see the noise the blur left. Taps are not weighted by
 *                          their own history length (inverse variance): that pulled stale light from long
 *                          histories into pixels the anti-lag had just shortened (docs/denoising.md).
 *                          With `min_length`, histories shorter than that (a fresh sample: disoccluded, or
 *                          the anti-lag dropped the history) are left to the passes, whose spatial variance
 *                          estimate already lets them blur such pixels hard.
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

/* The 7x7 neighbourhood estimate of a pixel (x, y) in pieces, so that a GPU can spread its taps over the
 * lanes of a warp (cuda_frame_post.cu) where one thread would walk all 49 while its neighbours with long
 * histories wait: begin, every tap (dx, dy) in any order, then sums combined by addition, then finish. */
typedef struct KSvgfNeighbourhood {
  KVec3 np; float zp;
  float inv_depth_scale; kint x; kint y;
  float s1; float s2; float weight_sum;  /* the taps' weighted moments and weights */
} KSvgfNeighbourhood;

KFN KSvgfNeighbourhood k_svgf_neighbourhood_begin(KGLOBAL const float* geometry, const KSvgfVarianceParams* p,
                                                  kint x, kint y) {
  KSvgfNeighbourhood n;
  KFloat4 gp = k_load4(geometry + 4 * (y * p->width + x));
  n.np = v3(gp.x, gp.y, gp.z);
  n.zp = gp.w;
  n.inv_depth_scale = k_atrous_inv_depth_scale(p->depth_sigma, gp.w, 1);
  n.x = x, n.y = y;
  n.s1 = 0.0f, n.s2 = 0.0f, n.weight_sum = 0.0f;
  return n;
}

/* Tap (dx, dy), each within +-K_SVGF_SPATIAL_RADIUS, into the sums: its moments (or its sample's luminance
 * where it has no history), weighted by the normal stop and the depth stop per pixel of distance. */
KFN void k_svgf_neighbourhood_tap(KSvgfNeighbourhood* n, KGLOBAL const float* illumination, KGLOBAL const float* moments,
                                  KGLOBAL const float* length, KGLOBAL const float* geometry,
                                  const KSvgfVarianceParams* p, kint dx, kint dy) {
  kint qx = n->x + dx, qy = n->y + dy;
  if (qy < 0 || qy >= p->height || qx < 0 || qx >= p->width) return;
  kint q = qy * p->width + qx;
  float m1, m2;
  if (p->have_history && length[q] > 0.0f) {
    m1 = moments[2 * q];
    m2 = moments[2 * q + 1];
  } else {
    KGLOBAL const float* c = illumination + 4 * q;
    if (!k_finite3(c[0], c[1], c[2])) return;
    m1 = k_atrous_luminance(c);
    m2 = m1 * m1;
  }
  if (!(k_fabs(m1) < 1e18f) || !(m2 < 3e38f)) return;
  float w = 1.0f;
  if (dx != 0 || dy != 0) {
    float exponent = 0.0f;
    KFloat4 gq = k_load4(geometry + 4 * q);
    w = k_atrous_geometry_stop(n->zp, n->np, gq.w, v3(gq.x, gq.y, gq.z), n->inv_depth_scale, p->normal_squarings,
                               &exponent);
    if (!(w > 0.0f)) return;
    kint ax = dx < 0 ? -dx : dx, ay = dy < 0 ? -dy : dy;
    exponent /= (float)(ax > ay ? ax : ay); /* relative depth per pixel of (Chebyshev) distance */
    if (exponent > 12.0f) return;
    w *= k_exp(-exponent);
  }
  n->s1 += w * m1;
  n->s2 += w * m2;
  n->weight_sum += w;
}

/* The neighbourhood's variance, boosted by short_history / length as SVGF does (few frames underestimate it). */
KFN float k_svgf_neighbourhood_variance(const KSvgfNeighbourhood* n, KGLOBAL const float* length,
                                        const KSvgfVarianceParams* p) {
  float history = p->have_history ? length[n->y * p->width + n->x] : 0.0f;
  float of_mean = p->of_mean ? 1.0f / k_fmax(history, 1.0f) : 1.0f;
  float v = 0.0f;
  if (n->weight_sum > 0.0f) {
    float mean = n->s1 / n->weight_sum;
    v = k_fmax(n->s2 / n->weight_sum - mean * mean, 0.0f);
  }
  return v * (p->short_history / k_fmax(history, 1.0f)) * of_mean;
}

/* 1 where the estimate reads the neighbourhood (the history is shorter than short_history, or there is
 * none), 0 where it reads the pixel's own temporal moments. */
KFN int k_svgf_variance_is_spatial(KGLOBAL const float* length, const KSvgfVarianceParams* p, kint x, kint y) {
  return !(p->have_history && length[y * p->width + x] >= p->short_history);
}

/* The pixel's variance from its own temporal moments (where it is not spatial: a long enough history). */
KFN float k_svgf_temporal_variance(KGLOBAL const float* moments, KGLOBAL const float* length,
                                   const KSvgfVarianceParams* p, kint x, kint y) {
  kint centre = y * p->width + x;
  float of_mean = p->of_mean ? 1.0f / k_fmax(length[centre], 1.0f) : 1.0f;
  return k_fmax(moments[2 * centre + 1] - moments[2 * centre] * moments[2 * centre], 0.0f) * of_mean;
}

/* The pixel's variance. `illumination` is the demodulated frame the passes filter (only its RGB is read);
 * moments and length are the reprojected history's (read only with have_history). */
KFN float k_svgf_variance_estimate(KGLOBAL const float* illumination, KGLOBAL const float* moments,
                                   KGLOBAL const float* length, KGLOBAL const float* geometry,
                                   const KSvgfVarianceParams* p, kint x, kint y) {
  if (!k_svgf_variance_is_spatial(length, p, x, y)) return k_svgf_temporal_variance(moments, length, p, x, y);
  KSvgfNeighbourhood n = k_svgf_neighbourhood_begin(geometry, p, x, y);
  for (kint dy = -K_SVGF_SPATIAL_RADIUS; dy <= K_SVGF_SPATIAL_RADIUS; ++dy)
    for (kint dx = -K_SVGF_SPATIAL_RADIUS; dx <= K_SVGF_SPATIAL_RADIUS; ++dx)
      k_svgf_neighbourhood_tap(&n, illumination, moments, length, geometry, p, dx, dy);
  return k_svgf_neighbourhood_variance(&n, length, p);
}

/* The estimate into a plane of one float a pixel. */
KFN void k_svgf_variance_pixel(KGLOBAL const float* illumination, KGLOBAL const float* moments,
                               KGLOBAL const float* length, KGLOBAL const float* geometry, KGLOBAL float* variance,
                               const KSvgfVarianceParams* p, kint x, kint y) {
  variance[y * p->width + x] = k_svgf_variance_estimate(illumination, moments, length, geometry, p, x, y);
}

typedef struct KHistoryFixParams {
  kint width; kint height; kint normal_squarings;
  kint guided;          /* 1: alpha carries the variance (kernel/atrous.h's guided passes); 0: alpha is 1 */
  float frames;         /* a history shorter than this many frames is fixed; 0: off */
  float stride;         /* pixels between taps at a one-frame history */
  float depth_sigma;    /* relative depth difference per pixel of tap distance (the a-trous filter's) */
  float color_sigma;    /* the luminance stop: standard deviations guided, relative difference unguided */
  float min_length;     /* a history shorter than this is left alone too; 0: none (a fresh sample is 1 frame) */
  float pad0;
} KHistoryFixParams;

/* The taps' spacing for a history of `length` frames: `stride` at one frame, down to 1 pixel just short of
 * `frames`; 0 where the pixel is left alone (history long enough, shorter than `min_length`, or none at all:
 * no reprojection, or non-finite samples that never entered it). */
KFN kint k_svgf_history_fix_stride(const KHistoryFixParams* p, float length) {
  if (!(length > 0.0f) || !(length < p->frames) || length < p->min_length) return 0;
  float shortness = p->frames > 1.0f ? (p->frames - k_fmax(length, 1.0f)) / (p->frames - 1.0f) : 1.0f;
  kint stride = (kint)(1.0f + (p->stride - 1.0f) * shortness + 0.5f);
  return stride < 1 ? 1 : stride;
}

/* One pixel from `in` into `out` (both RGBA illumination; unchanged pixels are copied). */
KFN void k_svgf_history_fix_pixel(KGLOBAL const float* in_rgba, KGLOBAL float* out_rgba, KGLOBAL const float* geometry,
                                  KGLOBAL const kuint* id, KGLOBAL const float* length, const KHistoryFixParams* p,
                                  kint x, kint y) {
  const float spline[3] = {0.375f, 0.25f, 0.0625f};
  kint centre = y * p->width + x;
  KFloat4 c = k_load4(in_rgba + 4 * centre);
  KGLOBAL float* out = out_rgba + 4 * centre;
  kint stride = k_svgf_history_fix_stride(p, length[centre]);
  if (stride == 0 || !k_finite3(c.x, c.y, c.z)) {
    out[0] = c.x, out[1] = c.y, out[2] = c.z, out[3] = c.w;
    return;
  }
  KFloat4 gp = k_load4(geometry + 4 * centre);
  float zp = gp.w;
  KVec3 np = v3(gp.x, gp.y, gp.z);
  kuint idp = id[centre];
  float lp = k_luminance3(c.x, c.y, c.z);
  /* The pixel's own variance, not the passes' 3x3 blur of it: the fix's stop is loose anyway. */
  float inv_luminance_scale = p->guided ? 1.0f / (p->color_sigma * k_sqrt(k_fmax(c.w, 0.0f)) + K_SVGF_LUMINANCE_EPSILON)
                                        : 0.0f;
  float sum[3] = {0.0f, 0.0f, 0.0f};
  float weight_sum = 0.0f, variance_sum = 0.0f;
  for (kint dy = -2; dy <= 2; ++dy) {
    kint qy = y + dy * stride;
    if (qy < 0 || qy >= p->height) continue;
    for (kint dx = -2; dx <= 2; ++dx) {
      kint qx = x + dx * stride;
      if (qx < 0 || qx >= p->width) continue;
      kint q = qy * p->width + qx;
      KFloat4 cq = k_load4(in_rgba + 4 * q);
      if (!k_finite3(cq.x, cq.y, cq.z)) continue;
      float w = spline[dx < 0 ? -dx : dx] * spline[dy < 0 ? -dy : dy];
      if (q != centre) {
        if (id[q] != idp || !(length[q] > 0.0f)) continue;
        float exponent = 0.0f; /* |zp - zq| */
        KFloat4 gq = k_load4(geometry + 4 * q);
        float stop = k_atrous_geometry_stop(zp, np, gq.w, v3(gq.x, gq.y, gq.z), 1.0f, p->normal_squarings, &exponent);
        if (!(stop > 0.0f)) continue;
        /* Relative to the nearer of the two depths, per pixel of (Chebyshev) distance: the wide taps reach
         * across silhouettes, and a far pixel must not take a near surface's light any more than the
         * other way round. */
        if (zp > 0.0f) {
          kint ax = dx < 0 ? -dx : dx, ay = dy < 0 ? -dy : dy;
          float distance = (float)((ax > ay ? ax : ay) * stride);
          exponent /= p->depth_sigma * k_fmin(zp, gq.w) * distance + 1e-6f;
        }
        float lq = k_luminance3(cq.x, cq.y, cq.z);
        exponent += p->guided ? k_fabs(lp - lq) * inv_luminance_scale
                              : k_fabs(lp - lq) / (p->color_sigma * 0.5f * (k_fabs(lp) + k_fabs(lq)) + 1e-4f);
        if (exponent > 12.0f) continue;
        w *= stop * k_exp(-exponent);
      }
      if (!(w > 0.0f)) continue;
      sum[0] += w * cq.x;
      sum[1] += w * cq.y;
      sum[2] += w * cq.z;
      weight_sum += w;
      if (p->guided) variance_sum += w * w * cq.w;
    }
  }
  float inv = 1.0f / weight_sum; /* the centre always counts */
  out[0] = sum[0] * inv;
  out[1] = sum[1] * inv;
  out[2] = sum[2] * inv;
  out[3] = p->guided ? variance_sum * inv * inv : c.w;
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
