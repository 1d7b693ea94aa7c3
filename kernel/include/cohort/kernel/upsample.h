/* Dynamic resolution's reconstruction (docs/denoising.md, "Dynamic resolution"): a frame whose paths were
 * traced at only some pixels (path_pattern.h) but whose G-buffer covers every pixel becomes a full image.
 *
 * Joint-bilateral upsampling (Kopf et al., "Joint Bilateral Upsampling", SIGGRAPH 2007) guided by the
 * full-resolution G-buffer: each pixel gathers the traced pixels of a (2r+1)^2 window, weighted by
 *   spatial     exp(-d^2 / (2 sigma^2)), sigma from the pattern's spacing (4 / sqrt(path_pixels) pixels)
 *   geometry    the a-trous filter's stops (atrous.h): a miss only takes misses, a surface only surfaces
 *               of the same entity (id), max(0, n_p . n_q) ^ (2 ^ normal_squarings), and
 *               exp(-|z_p - z_q| / (depth_sigma * z_p * d)), relative to the depth and the tap's distance
 *   albedo      exp(-sum|a_p - a_q| / (albedo_sigma * sum(a_p + a_q))): a texel of another material (a light
 *               panel, whose albedo holds its emission, beside a grey ceiling) lends little of its light
 * and mixes their illumination (colour / albedo, illumination.h), which it multiplies back by the pixel's
 * own albedo: textures stay as sharp as the G-buffer, edges as sharp as the depth, normal and id planes.
 * Traced pixels are filtered too (their own weight 1), so traced and filled pixels have the same noise.
 * A pixel no traced tap matches (a thin object between samples) falls back to the spatial weights over
 * taps of its kind (surface or miss), then over all taps: never black where light was traced nearby.
 *
 * Planes: the host's G-buffer layout (core/gbuffer.h): colour RGBA floats (only traced pixels are read),
 * depth one float a pixel, normal and albedo three, id one uint. */
#ifndef COHORT_KERNEL_UPSAMPLE_H
#define COHORT_KERNEL_UPSAMPLE_H
#include "atrous.h"
#include "path_pattern.h"

#define K_UPSAMPLE_JOINT_BILATERAL 0
#define K_UPSAMPLE_NEAREST 1 /* the nearest traced pixel's colour: no guide (a baseline) */

typedef struct KUpsampleParams {
  kint width; kint height; kuint path_pixels; kuint path_phase;
  kint radius; kint normal_squarings; float depth_sigma; float inv_two_sigma2;
  float albedo_sigma; float pad0; float pad1; float pad2;
} KUpsampleParams;

/* The pattern's mean distance between traced pixels, in pixels. */
KFN float k_upsample_spacing(kuint path_pixels) {
  kuint k = path_pixels == 0u || path_pixels > K_PATH_PATTERN_PIXELS ? K_PATH_PATTERN_PIXELS : path_pixels;
  return 4.0f / k_sqrt((float)k);
}

/* Parameters for a pattern: the window reaches 1.5 spacings, the spatial sigma is 0.6 of one. */
KFN KUpsampleParams k_upsample_params(kint width, kint height, kuint path_pixels, kuint path_phase) {
  KUpsampleParams p;
  float spacing = k_upsample_spacing(path_pixels);
  float sigma = 0.6f * spacing;
  p.width = width;
  p.height = height;
  p.path_pixels = path_pixels;
  p.path_phase = path_phase;
  p.radius = (kint)(1.5f * spacing + 0.5f);
  if (p.radius < 1) p.radius = 1;
  if (p.radius > 6) p.radius = 6;
  p.normal_squarings = 5; /* n . n ^ 32 */
  p.depth_sigma = 0.02f;
  p.inv_two_sigma2 = 1.0f / (2.0f * sigma * sigma);
  p.albedo_sigma = 0.1f;
  p.pad0 = p.pad1 = p.pad2 = 0.0f;
  return p;
}

KFN float k_upsample_channel_albedo(KGLOBAL const float* albedo, kint p, int k) {
  return k_fmax(albedo[3 * p + k], K_ILLUMINATION_LEAST_ALBEDO);
}

/* How far two albedos lie apart, relative to their size: 0 for equal ones, 1 for black against any colour. */
KFN float k_upsample_albedo_difference(KGLOBAL const float* albedo, kint p, kint q) {
  float difference = 0.0f, size = 0.06f;
  for (int k = 0; k < 3; ++k) {
    difference += k_fabs(albedo[3 * p + k] - albedo[3 * q + k]);
    size += albedo[3 * p + k] + albedo[3 * q + k];
  }
  return difference / size;
}

KFN void k_upsample_pixel(KGLOBAL const float* in_rgba, KGLOBAL const float* depth, KGLOBAL const float* normal,
                          KGLOBAL const float* albedo, KGLOBAL const kuint* id, KGLOBAL float* out_rgba,
                          const KUpsampleParams* p, int method, kint x, kint y) {
  kint centre = y * p->width + x;
  float zp = depth[centre];
  kuint idp = id[centre];
  KVec3 np = v3(normal[3 * centre], normal[3 * centre + 1], normal[3 * centre + 2]);
  /* Three sums: guided (geometry and spatial), spatial over taps of the pixel's kind, spatial over all. */
  float sum[3][3] = {{0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 0.0f}};
  float weight[3] = {0.0f, 0.0f, 0.0f};
  float nearest_d2 = 1e30f;
  kint nearest = -1;
  for (kint dy = -p->radius; dy <= p->radius; ++dy) {
    kint qy = y + dy;
    if (qy < 0 || qy >= p->height) continue;
    for (kint dx = -p->radius; dx <= p->radius; ++dx) {
      kint qx = x + dx;
      if (qx < 0 || qx >= p->width) continue;
      if (!k_pixel_traces_path(p->path_pixels, p->path_phase, (kuint)qx, (kuint)qy)) continue;
      kint q = qy * p->width + qx;
      KGLOBAL const float* cq = in_rgba + 4 * q;
      if (!k_finite3(cq[0], cq[1], cq[2])) continue;
      float d2 = (float)(dx * dx + dy * dy);
      if (d2 < nearest_d2) {
        nearest_d2 = d2;
        nearest = q;
      }
      if (method == K_UPSAMPLE_NEAREST) continue;
      float illumination[3];
      for (int k = 0; k < 3; ++k) illumination[k] = cq[k] / k_upsample_channel_albedo(albedo, q, k);
      float spatial = k_exp(-d2 * p->inv_two_sigma2);
      int same_kind = (zp > 0.0f) == (depth[q] > 0.0f);
      float guided = 0.0f;
      if (q == centre) {
        guided = 1.0f;
      } else if (same_kind && id[q] == idp) {
        float exponent = 0.0f;
        float inv_depth_scale = zp > 0.0f ? 1.0f / (p->depth_sigma * zp * k_sqrt(d2) + 1e-6f) : 0.0f;
        float geometry = k_atrous_geometry(zp, np, inv_depth_scale, p->normal_squarings, depth, normal, q, &exponent);
        exponent += k_upsample_albedo_difference(albedo, centre, q) / p->albedo_sigma;
        if (geometry > 0.0f && exponent < 12.0f) guided = spatial * geometry * k_exp(-exponent);
      }
      for (int k = 0; k < 3; ++k) {
        sum[0][k] += guided * illumination[k];
        if (same_kind) sum[1][k] += spatial * illumination[k];
        sum[2][k] += spatial * illumination[k];
      }
      weight[0] += guided;
      if (same_kind) weight[1] += spatial;
      weight[2] += spatial;
    }
  }
  KGLOBAL float* out = out_rgba + 4 * centre;
  out[3] = 1.0f;
  if (method == K_UPSAMPLE_NEAREST) {
    for (int k = 0; k < 3; ++k) out[k] = nearest >= 0 ? in_rgba[4 * nearest + k] : 0.0f;
    return;
  }
  int use = weight[0] > 1e-4f ? 0 : weight[1] > 0.0f ? 1 : 2;
  float inv = weight[use] > 0.0f ? 1.0f / weight[use] : 0.0f;
  for (int k = 0; k < 3; ++k) out[k] = sum[use][k] * inv * k_upsample_channel_albedo(albedo, centre, k);
}

#endif
