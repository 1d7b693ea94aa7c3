/* The edge-aware a-trous wavelet filter (Dammertz et al., "Edge-Avoiding A-Trous Wavelet Transform for
 * fast Global Illumination Filtering", HPG 2010; the spatial filter of SVGF with a fixed, relative
 * luminance stop instead of SVGF's variance: kernel/svgf.h has that one), one pass at one pixel. Passes run with step 1, 2, 4, ...: each is a 5x5 B3-spline kernel
 * whose taps lie `step` pixels apart, so four passes cover a 61-pixel footprint for 100 taps a pixel.
 * A tap's weight is the spline's times three edge stops, so that light does not leak across geometry:
 *   normal      max(0, n_p . n_q) ^ (2 ^ normal_squarings)   (squarings, not pow: 64 is 6 multiplies)
 *   depth       exp(-|z_p - z_q| / (depth_sigma * z_p * step))     (relative: any scale of map)
 *   luminance   exp(-|l_p - l_q| / (color_sigma * (l_p + l_q) / 2 + 1e-4))   (relative: HDR)
 * Camera misses (depth 0) only mix with misses. Taps whose colour is not finite are left out; the centre
 * always counts, so a pixel keeps its colour where every neighbour is across an edge. The two exponential
 * stops are one exp of their summed arguments: transcendental calls set this filter's cost on the CPU.
 * Colour planes are RGBA floats; the passes read normal and depth packed into one RGBA plane
 * (k_atrous_pack_geometry from the host's G-buffer layout, core/gbuffer.h). */
#ifndef COHORT_KERNEL_ATROUS_H
#define COHORT_KERNEL_ATROUS_H
#include "illumination.h"
#include "vec.h"

typedef struct KAtrousParams {
  kint width; kint height; kint step; kint normal_squarings;
  float depth_sigma; float color_sigma; float pad0; float pad1;
} KAtrousParams;

/* Illumination = colour / albedo before the passes, colour = illumination * albedo after (multiply = 1),
 * so textures stay sharp; black surfaces divide by the least albedo and multiply back by the same. */
#define K_ATROUS_LEAST_ALBEDO K_ILLUMINATION_LEAST_ALBEDO
KFN void k_atrous_modulate(KGLOBAL const float* in_rgba, KGLOBAL const float* albedo, KGLOBAL float* out_rgba, kint p,
                           int multiply) {
  for (int k = 0; k < 3; ++k) {
    float a = k_fmax(albedo[3 * p + k], K_ATROUS_LEAST_ALBEDO);
    out_rgba[4 * p + k] = multiply ? in_rgba[4 * p + k] * a : in_rgba[4 * p + k] / a;
  }
  out_rgba[4 * p + 3] = 1.0f;
}

KFN float k_atrous_luminance(KGLOBAL const float* c) { return k_luminance3(c[0], c[1], c[2]); }

/* The geometric stops between a pixel at depth zp (0: a miss) with normal np and a tap at depth zq with
 * normal nq: returns the normal stop's factor (0: the tap lies across an edge, or is a surface where the
 * pixel is a miss or the other way round) and adds the depth stop's argument to *exponent. */
KFN float k_atrous_geometry_stop(float zp, KVec3 np, float zq, KVec3 nq, float inv_depth_scale, kint normal_squarings,
                                 float* exponent) {
  if ((zp > 0.0f) != (zq > 0.0f)) return 0.0f; /* a surface and a miss */
  if (!(zp > 0.0f)) return 1.0f;
  float cosine = k_fmax(v3_dot(np, nq), 0.0f);
  for (kint s = 0; s < normal_squarings; ++s) cosine *= cosine;
  if (cosine < 1e-4f) return 0.0f; /* across an edge; and the squarings would reach subnormals */
  *exponent += k_fabs(zp - zq) * inv_depth_scale;
  return cosine;
}

/* The same stops for tap q of the G-buffer's depth and normal planes (the variance estimate and the
 * upsampler read those). */
KFN float k_atrous_geometry(float zp, KVec3 np, float inv_depth_scale, kint normal_squarings, KGLOBAL const float* depth,
                            KGLOBAL const float* normal, kint q, float* exponent) {
  KVec3 nq = v3(normal[3 * q], normal[3 * q + 1], normal[3 * q + 2]);
  return k_atrous_geometry_stop(zp, np, depth[q], nq, inv_depth_scale, normal_squarings, exponent);
}

/* The passes read normal and depth of a tap as one 16-byte load from a packed plane (x, y, z: the
 * normal; w: the depth), where the planes take four loads: on GPUs the taps' loads set the cost. */
KFN void k_atrous_pack_geometry(KGLOBAL const float* depth, KGLOBAL const float* normal, KGLOBAL float* geometry,
                                kint p) {
  geometry[4 * p] = normal[3 * p];
  geometry[4 * p + 1] = normal[3 * p + 1];
  geometry[4 * p + 2] = normal[3 * p + 2];
  geometry[4 * p + 3] = depth[p];
}

KFN float k_atrous_inv_depth_scale(float depth_sigma, float zp, kint step) {
  return zp > 0.0f ? 1.0f / (depth_sigma * zp * (float)step + 1e-6f) : 0.0f;
}

/* One pass at one pixel, for either luminance stop. `geometry` is the packed plane above. Guided (the
 * variance guide, kernel/svgf.h): the colour planes carry each pixel's luminance variance in alpha, the
 * stop is |l_p - l_q| * inv_luminance_scale (from the pixel's variance) and the variance is filtered along
 * with the colour, weights squared, into out's alpha; unguided (inv_luminance_scale unused), the fixed
 * relative stop above and alpha 1. */
KFN void k_atrous_pass_pixel(KGLOBAL const float* in_rgba, KGLOBAL float* out_rgba, KGLOBAL const float* geometry,
                             const KAtrousParams* p, int guided, float inv_luminance_scale, kint x, kint y) {
  const float spline[3] = {0.375f, 0.25f, 0.0625f};
  kint centre = y * p->width + x;
  KFloat4 c = k_load4(in_rgba + 4 * centre);
  KFloat4 gp = k_load4(geometry + 4 * centre);
  float zp = gp.w;
  KVec3 np = v3(gp.x, gp.y, gp.z);
  int centre_ok = k_finite3(c.x, c.y, c.z);
  float lp = centre_ok ? k_luminance3(c.x, c.y, c.z) : 0.0f;
  float inv_depth_scale = k_atrous_inv_depth_scale(p->depth_sigma, zp, p->step);
  float sum[3] = {0.0f, 0.0f, 0.0f};
  float weight_sum = 0.0f, variance_sum = 0.0f;
  for (kint dy = -2; dy <= 2; ++dy) {
    kint qy = y + dy * p->step;
    if (qy < 0 || qy >= p->height) continue;
    for (kint dx = -2; dx <= 2; ++dx) {
      kint qx = x + dx * p->step;
      if (qx < 0 || qx >= p->width) continue;
      kint q = qy * p->width + qx;
      KFloat4 cq = k_load4(in_rgba + 4 * q);
      if (!k_finite3(cq.x, cq.y, cq.z)) continue;
      float w = spline[dx < 0 ? -dx : dx] * spline[dy < 0 ? -dy : dy];
      if (q != centre) {
        float exponent = 0.0f;
        KFloat4 gq = k_load4(geometry + 4 * q);
        float stop = k_atrous_geometry_stop(zp, np, gq.w, v3(gq.x, gq.y, gq.z), inv_depth_scale, p->normal_squarings,
                                            &exponent);
        if (!(stop > 0.0f)) continue;
        w *= stop;
        if (centre_ok) {
          float lq = k_luminance3(cq.x, cq.y, cq.z);
          exponent += guided ? k_fabs(lp - lq) * inv_luminance_scale
                             : k_fabs(lp - lq) / (p->color_sigma * 0.5f * (k_fabs(lp) + k_fabs(lq)) + 1e-4f);
        }
        if (!(w > 0.0f) || exponent > 12.0f) continue; /* weight below 6e-6 of the stops' best: left out, and
                                                          so are exp's subnormal results, slow on CPUs */
        w *= k_exp(-exponent);
      }
      if (!(w > 0.0f)) continue;
      sum[0] += w * cq.x;
      sum[1] += w * cq.y;
      sum[2] += w * cq.z;
      weight_sum += w;
      if (guided) variance_sum += w * w * cq.w;
    }
  }
  float inv = weight_sum > 0.0f ? 1.0f / weight_sum : 0.0f;
  KGLOBAL float* out = out_rgba + 4 * centre;
  out[0] = sum[0] * inv;
  out[1] = sum[1] * inv;
  out[2] = sum[2] * inv;
  out[3] = guided ? variance_sum * inv * inv : 1.0f;
}

/* One pass with the fixed relative luminance stop. */
KFN void k_atrous_pixel(KGLOBAL const float* in_rgba, KGLOBAL float* out_rgba, KGLOBAL const float* geometry,
                        const KAtrousParams* p, kint x, kint y) {
  k_atrous_pass_pixel(in_rgba, out_rgba, geometry, p, 0, 0.0f, x, y);
}

#endif
