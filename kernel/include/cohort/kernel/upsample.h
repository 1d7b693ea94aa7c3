/* Dynamic resolution's reconstruction (docs/denoising.md, "Dynamic resolution"): a frame whose paths were
 * traced at only some pixels (path_pattern.h) but whose G-buffer covers every pixel becomes a full image.
 *
 * Joint-bilateral upsampling (Kopf et al., "Joint Bilateral Upsampling", SIGGRAPH 2007) guided by the
 * full-resolution G-buffer: each pixel gathers the traced pixels within r + 1/2 pixels, weighted by
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
  float albedo_sigma; kuint traced_mask; float pad1; float pad2;
} KUpsampleParams;
/* traced_mask: bit 4 * (y % 4) + x % 4 is set where the pattern traces (the pattern repeats every 4). */

/* The pattern's mean distance between traced pixels, in pixels. */
KFN float k_upsample_spacing(kuint path_pixels) {
  kuint k = path_pixels == 0u || path_pixels > K_PATH_PATTERN_PIXELS ? K_PATH_PATTERN_PIXELS : path_pixels;
  return 4.0f / k_sqrt((float)k);
}

/* Parameters for a pattern: a round window of one spacing (plus half a pixel), the spatial sigma 0.6 of one
 * (measured on the test map at scale 0.5: a reach of 1.5 spacings costs twice the taps for no less error). */
KFN KUpsampleParams k_upsample_params(kint width, kint height, kuint path_pixels, kuint path_phase) {
  KUpsampleParams p;
  float spacing = k_upsample_spacing(path_pixels);
  float sigma = 0.6f * spacing;
  p.width = width;
  p.height = height;
  p.path_pixels = path_pixels;
  p.path_phase = path_phase;
  p.radius = (kint)(spacing + 0.5f);
  if (p.radius < 1) p.radius = 1;
  if (p.radius > 6) p.radius = 6;
  p.normal_squarings = 5; /* n . n ^ 32 */
  p.depth_sigma = 0.02f;
  p.inv_two_sigma2 = 1.0f / (2.0f * sigma * sigma);
  p.albedo_sigma = 0.1f;
  p.traced_mask = 0u;
  for (kuint b = 0u; b < K_PATH_PATTERN_PIXELS; ++b)
    if (k_pixel_traces_path(path_pixels, path_phase, b % 4u, b / 4u)) p.traced_mask |= 1u << b;
  p.pad1 = p.pad2 = 0.0f;
  return p;
}

KFN float k_upsample_channel_albedo(KGLOBAL const float* albedo, kint p, int k) {
  return k_fmax(albedo[3 * p + k], K_ILLUMINATION_LEAST_ALBEDO);
}

/* How far albedo ap and tap q's lie apart, relative to their size: 0 for equal ones, 1 for black against
 * any colour. */
KFN float k_upsample_albedo_difference(KVec3 ap, KGLOBAL const float* albedo, kint q) {
  KVec3 aq = v3(albedo[3 * q], albedo[3 * q + 1], albedo[3 * q + 2]);
  float difference = k_fabs(ap.x - aq.x) + k_fabs(ap.y - aq.y) + k_fabs(ap.z - aq.z);
  return difference / (0.06f + ap.x + ap.y + ap.z + aq.x + aq.y + aq.z);
}

/* Pass 1, at traced pixels only: the illumination (colour over albedo) the sweeps read, so each traced
 * pixel is divided once rather than once per pixel whose window holds it. Other pixels are not written. */
KFN void k_upsample_demodulate_pixel(KGLOBAL const float* in_rgba, KGLOBAL const float* albedo,
                                     KGLOBAL float* illumination, const KUpsampleParams* p, kint x, kint y) {
  if (!((p->traced_mask >> (4 * (y & 3) + (x & 3))) & 1u)) return;
  kint q = y * p->width + x;
  for (int k = 0; k < 3; ++k) illumination[4 * q + k] = in_rgba[4 * q + k] / k_upsample_channel_albedo(albedo, q, k);
  illumination[4 * q + 3] = 1.0f;
}

/* First coordinate >= from that is congruent to phase modulo 4. */
KFN kint k_upsample_first(kint from, kint phase) { return from + (((phase - from) % 4) + 4) % 4; }

#define K_UPSAMPLE_GUIDED 0      /* spatial x geometry x albedo weights */
#define K_UPSAMPLE_SAME_KIND 1   /* spatial weights over taps of the pixel's kind (surface or miss) */
#define K_UPSAMPLE_SPATIAL 2     /* spatial weights over every tap */
#define K_UPSAMPLE_CLOSEST 3     /* the closest tap only (sum = its colour) */

/* One sweep over the traced pixels of the window around centre (x, y), weighted as `weights` says: adds
 * the weighted RGBA `samples` (illumination; colour for K_UPSAMPLE_CLOSEST) to sum, leaving out those that
 * are not finite, and returns the summed weight. The pattern repeats every 4 pixels, so the sweep visits
 * each of the block's traced positions and steps by 4 from there: only traced pixels are read. */
KFN float k_upsample_sweep(KGLOBAL const float* samples, KGLOBAL const float* depth, KGLOBAL const float* normal,
                           KGLOBAL const float* albedo, KGLOBAL const kuint* id, const KUpsampleParams* p, kint x,
                           kint y, int weights, float* sum) {
  kint centre = y * p->width + x;
  float zp = depth[centre];
  kuint idp = id[centre];
  KVec3 np = v3(normal[3 * centre], normal[3 * centre + 1], normal[3 * centre + 2]);
  KVec3 ap = v3(albedo[3 * centre], albedo[3 * centre + 1], albedo[3 * centre + 2]);
  float inv_depth_scale = zp > 0.0f ? 1.0f / (p->depth_sigma * zp) : 0.0f;
  float inv_albedo_sigma = 1.0f / p->albedo_sigma;
  float weight = 0.0f, closest_d2 = 1e30f;
  kint r = p->radius;
  float reach2 = ((float)r + 0.5f) * ((float)r + 0.5f); /* a round window: the corners weigh little */
  for (kint by = 0; by < 4; ++by)
    for (kint bx = 0; bx < 4; ++bx) {
      if (!((p->traced_mask >> (4 * by + bx)) & 1u)) continue;
      for (kint qy = k_upsample_first(y - r, by); qy <= y + r; qy += 4) {
        if (qy < 0 || qy >= p->height) continue;
        for (kint qx = k_upsample_first(x - r, bx); qx <= x + r; qx += 4) {
          if (qx < 0 || qx >= p->width) continue;
          kint q = qy * p->width + qx;
          float d2 = (float)((qx - x) * (qx - x) + (qy - y) * (qy - y));
          if (d2 > reach2) continue;
          KGLOBAL const float* cq = samples + 4 * q;
          if (!k_finite3(cq[0], cq[1], cq[2])) continue;
          if (weights == K_UPSAMPLE_CLOSEST) {
            if (d2 < closest_d2) {
              closest_d2 = d2;
              sum[0] = cq[0], sum[1] = cq[1], sum[2] = cq[2];
              weight = 1.0f;
            }
            continue;
          }
          float exponent = d2 * p->inv_two_sigma2;
          float w = 1.0f;
          int same_kind = (zp > 0.0f) == (depth[q] > 0.0f);
          if (weights == K_UPSAMPLE_SAME_KIND && !same_kind) continue;
          if (weights == K_UPSAMPLE_GUIDED && q != centre) {
            if (!same_kind || id[q] != idp) continue;
            float distance_exponent = 0.0f;
            w = k_atrous_geometry(zp, np, inv_depth_scale, p->normal_squarings, depth, normal, q, &distance_exponent);
            if (!(w > 0.0f)) continue;
            exponent += distance_exponent / k_sqrt(d2) + k_upsample_albedo_difference(ap, albedo, q) * inv_albedo_sigma;
            if (exponent > 12.0f) continue; /* below 6e-6: left out, and so are exp's slow subnormals */
          }
          w *= k_exp(-exponent);
          for (int k = 0; k < 3; ++k) sum[k] += w * cq[k];
          weight += w;
        }
      }
    }
  return weight;
}

/* Pass 2, at every pixel: the reconstruction. illumination: pass 1's plane (not read by nearest). */
KFN void k_upsample_pixel(KGLOBAL const float* in_rgba, KGLOBAL const float* illumination, KGLOBAL const float* depth, KGLOBAL const float* normal,
                          KGLOBAL const float* albedo, KGLOBAL const kuint* id, KGLOBAL float* out_rgba,
                          const KUpsampleParams* p, int method, kint x, kint y) {
  kint centre = y * p->width + x;
  KGLOBAL float* out = out_rgba + 4 * centre;
  float sum[3] = {0.0f, 0.0f, 0.0f};
  out[3] = 1.0f;
  if (method == K_UPSAMPLE_NEAREST) {
    k_upsample_sweep(in_rgba, depth, normal, albedo, id, p, x, y, K_UPSAMPLE_CLOSEST, sum);
    out[0] = sum[0], out[1] = sum[1], out[2] = sum[2];
    return;
  }
  float weight = k_upsample_sweep(illumination, depth, normal, albedo, id, p, x, y, K_UPSAMPLE_GUIDED, sum);
  for (int fallback = K_UPSAMPLE_SAME_KIND; !(weight > 1e-4f) && fallback <= K_UPSAMPLE_SPATIAL; ++fallback) {
    sum[0] = sum[1] = sum[2] = 0.0f;
    weight = k_upsample_sweep(illumination, depth, normal, albedo, id, p, x, y, fallback, sum);
  }
  float inv = weight > 0.0f ? 1.0f / weight : 0.0f;
  for (int k = 0; k < 3; ++k) out[k] = sum[k] * inv * k_upsample_channel_albedo(albedo, centre, k);
}

#endif
