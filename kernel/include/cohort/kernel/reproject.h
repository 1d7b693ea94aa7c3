/* Temporal accumulation with reprojection, one pixel at a time (core/reprojection.h explains the method:
 * history fetched through the motion vectors, taps tested for the same surface, neighbourhood clamp in
 * YCoCg where the pixel moved, blend by history length). Written once here so the host's threads and a
 * GPU run the same arithmetic (C++, CUDA and OpenCL C).
 *
 * Two passes a frame:
 *   k_reproject_prepare  the fresh frame in YCoCg, w = 1 where the sample is finite, 0 where it is not;
 *   k_reproject_pixel    reads the previous frame's state and writes the next state (ping-pong).
 * Planes follow the host's G-buffer layout (core/gbuffer.h): one float a pixel for depths, two for
 * motion, three for normals, one kuint for ids; colours are RGBA floats.
 *
 * With `moments` set, the history also keeps the first and second moments of the illumination's luminance
 * (kernel/illumination.h; two floats a pixel), fetched through the same taps and blended with the same
 * weight as the colour, so that M2 - M1^2 is the pixel's temporal variance (SVGF, Schied et al. 2017; the
 * a-trous filter's luminance stop, kernel/svgf.h). Non-finite samples never enter them either.
 *
 * With `footprint_taps` set (planes from each pixel's jittered first hit, K_AUX_PATH_FIRST_HIT), a silhouette
 * pixel's sample lands on the near surface one frame and on the far one the next, so its id, depth and normal
 * flip from frame to frame and the same-surface test alone would restart its history at every flip: those
 * pixels would stay at about one sample. Centre rays do not flip (one fixed ray a pixel), and there every
 * sample of the pixel, whichever surface it met, enters one history: the pixel converges to the mix of the
 * surfaces its footprint covers. k_reproject_footprint_tap keeps that: see there. */
#ifndef COHORT_KERNEL_REPROJECT_H
#define COHORT_KERNEL_REPROJECT_H
#include "illumination.h"
#include "vec.h"

typedef struct KReprojectParams {
  kint width; kint height; kint have_history;
  kint moments;           /* 1: keep the luminance moments too (reads the fresh albedo and both moment planes) */
  float max_history;      /* frames: 1 / max_history is the least weight of a new sample */
  float depth_tolerance;  /* relative depth difference above which a history tap is another surface */
  float normal_cos;       /* least cosine between the normals of a pixel and its history tap */
  float clamp_sigma;      /* neighbourhood box half-width in standard deviations (moving pixels) */
  float still_motion;     /* pixels: motion below this counts as no motion (no clamp) */
  float anti_lag_sigma;   /* moving pixels: history luma off the fresh 5x5 mean by more than this many standard
                             errors (plus anti_lag_relative of the mean) is stale lighting; 0: off */
  float anti_lag_relative;
  kint footprint_taps;    /* 1: the planes come from each pixel's jittered sample (K_AUX_PATH_FIRST_HIT): history
                             taps of another surface that still lies in the pixel's footprint count too */
} KReprojectParams;

/* The fresh planes of one frame. */
typedef struct KReprojectFresh {
  KGLOBAL const float* rgba;
  KGLOBAL const float* ycocgw;  /* from k_reproject_prepare */
  KGLOBAL const float* depth;
  KGLOBAL const float* prev_depth;
  KGLOBAL const float* motion;
  KGLOBAL const float* normal;
  KGLOBAL const kuint* id;
  KGLOBAL const float* albedo;  /* read only with moments */
} KReprojectFresh;

/* The history a pixel reads (the previous frame's state). */
typedef struct KReprojectHistory {
  KGLOBAL const float* rgba;
  KGLOBAL const float* length;
  KGLOBAL const float* depth;
  KGLOBAL const float* normal;
  KGLOBAL const kuint* id;
  KGLOBAL const float* moments; /* luminance M1, M2; read only with moments */
} KReprojectHistory;

/* The state a pixel writes (the next frame's history). */
typedef struct KReprojectState {
  KGLOBAL float* rgba;
  KGLOBAL float* length;
  KGLOBAL float* depth;
  KGLOBAL float* normal;
  KGLOBAL kuint* id;
  KGLOBAL float* moments;       /* written only with moments */
} KReprojectState;

KFN void k_reproject_prepare(KGLOBAL const float* rgba, KGLOBAL float* ycocgw, kint p) {
  KGLOBAL const float* c = rgba + 4 * p;
  KGLOBAL float* out = ycocgw + 4 * p;
  if (k_finite3(c[0], c[1], c[2])) {
    out[0] = 0.25f * c[0] + 0.5f * c[1] + 0.25f * c[2];
    out[1] = 0.5f * c[0] - 0.5f * c[2];
    out[2] = -0.25f * c[0] + 0.5f * c[1] - 0.25f * c[2];
    out[3] = 1.0f;
  } else {
    out[0] = 0.0f; out[1] = 0.0f; out[2] = 0.0f; out[3] = 0.0f;
  }
}

KFN KVec3 k_reproject_to_ycocg(KVec3 c) {
  return v3(0.25f * c.x + 0.5f * c.y + 0.25f * c.z, 0.5f * c.x - 0.5f * c.z, -0.25f * c.x + 0.5f * c.y - 0.25f * c.z);
}
KFN KVec3 k_reproject_from_ycocg(KVec3 v) {
  float t = v.x - v.z;
  return v3(t + v.y, v.x + v.z, t - v.y);
}

/* Mean and variance of the finite fresh samples of the 3x3 neighbourhood, in YCoCg; returns the count. The
 * neighbourhoods read RGBA texels with k_load4: one 128-bit load on GPUs, where a float pointer alone gives the
 * compiler no alignment to merge scalar loads by. */
KFN int k_reproject_moments(const KReprojectParams* p, KGLOBAL const float* ycocgw, kint x, kint y, KVec3* m1,
                            KVec3* m2) {
  int count = 0;
  *m1 = v3s(0.0f);
  *m2 = v3s(0.0f);
  for (kint dy = -1; dy <= 1; ++dy) {
    kint ny = y + dy;
    if (ny < 0 || ny >= p->height) continue;
    for (kint dx = -1; dx <= 1; ++dx) {
      kint nx = x + dx;
      if (nx < 0 || nx >= p->width) continue;
      KFloat4 v = k_load4(ycocgw + 4 * (ny * p->width + nx));
      if (v.w == 0.0f) continue;
      KVec3 s = v3(v.x, v.y, v.z);
      *m1 = v3_add(*m1, s);
      *m2 = v3_add(*m2, v3_mul(s, s));
      ++count;
    }
  }
  return count;
}

/* Anti-lag (moving pixels): has the lighting changed under the history? The clamp's 3x3 box spans the
 * noise of one sample (at 1 spp wider than most lighting changes: a flashlight that moves with the camera,
 * a flickering light, a door casting new light), so a long history lags. Compared here: the mean luma of
 * the 5x5 fresh samples around the pixel and of the history around the reprojected point, over the same
 * taps (pairs on the same object), so textures and edges cancel and only the change and the noise of the
 * fresh mean remain. Returns the factor (0, 1] to scale the history length by: 1 while the difference is
 * within anti_lag_sigma standard errors of the fresh mean (plus anti_lag_relative of it), the ratio of
 * that bound to the difference beyond. */
KFN float k_reproject_anti_lag(const KReprojectParams* p, const KReprojectFresh* fresh,
                               const KReprojectHistory* history, kint x, kint y, float hx, float hy) {
  kint cx = (kint)k_floor(hx + 0.5f), cy = (kint)k_floor(hy + 0.5f);
  float sf = 0.0f, sf2 = 0.0f, sh = 0.0f;
  int count = 0;
  for (kint dy = -2; dy <= 2; ++dy) {
    kint fy = y + dy, ty = cy + dy;
    if (fy < 0 || fy >= p->height || ty < 0 || ty >= p->height) continue;
    for (kint dx = -2; dx <= 2; ++dx) {
      kint fx = x + dx, tx = cx + dx;
      if (fx < 0 || fx >= p->width || tx < 0 || tx >= p->width) continue;
      kint f = fy * p->width + fx, q = ty * p->width + tx;
      KFloat4 v = k_load4(fresh->ycocgw + 4 * f);
      if (v.w == 0.0f || history->id[q] != fresh->id[f] || !(history->length[q] > 0.0f)) continue;
      KFloat4 h = k_load4(history->rgba + 4 * q);
      sf += v.x;
      sf2 += v.x * v.x;
      sh += 0.25f * h.x + 0.5f * h.y + 0.25f * h.z;
      ++count;
    }
  }
  if (count < 4) return 1.0f;
  float inv = 1.0f / (float)count;
  float mean = sf * inv;
  float standard_error = k_sqrt(k_fmax(sf2 * inv - mean * mean, 0.0f) * inv);
  float bound = p->anti_lag_sigma * standard_error + p->anti_lag_relative * k_fabs(mean) + 1e-6f;
  float difference = k_fabs(sh * inv - mean);
  return difference > bound ? bound / difference : 1.0f;
}

/* A history tap saw the surface (id, depth in the previous camera, normal) given: does it match? Misses match
 * misses by id alone. */
KFN int k_reproject_tap_matches(const KReprojectParams* p, const KReprojectHistory* history, kint q, kuint id,
                                float expected_depth, KVec3 n) {
  if (history->id[q] != id) return 0;
  if (id == 0xFFFFFFFFu) return 1;
  if (k_fabs(history->depth[q] - expected_depth) > p->depth_tolerance * k_fmax(expected_depth, 1e-3f)) return 0;
  return v3_dot(n, v3_load_g(history->normal + 3 * q)) >= p->normal_cos;
}

/* footprint_taps: a tap may count although it saw another surface than this frame's sample where that surface
 * is still inside the pixel's footprint: one of the 8 fresh neighbours saw it (same id, the tap's depth at that
 * neighbour's previous depth, same orientation) and moved with this pixel (motion vectors within
 * K_REPROJECT_FOOTPRINT_MOTION pixels). The motion test keeps the door's history out of the doorway it uncovers:
 * there the door's neighbours moved and the uncovered pixel did not. Only where the taps of this sample's own
 * surface carry less than K_REPROJECT_FOOTPRINT_SHARE of the bilinear weight: with a moving camera, a pixel wholly
 * on one surface next to an edge has taps of the other surface too, and taking them would blur the edge.
 * Measured on the test map's scenario (docs/denoising.md, "Silhouettes with first hits"): motion 0.1, 0.25,
 * 0.5, 1 px and shares 0.25, 0.5, 0.75 and any (every failed tap) tried; 0.25 px and 0.5 did best on the door
 * and the doorway. */
#define K_REPROJECT_FOOTPRINT_MOTION 0.25f
#define K_REPROJECT_FOOTPRINT_SHARE 0.5f
KFN int k_reproject_footprint_tap(const KReprojectParams* p, const KReprojectFresh* fresh,
                                  const KReprojectHistory* history, kint q, kint x, kint y, float mx, float my) {
  for (kint dy = -1; dy <= 1; ++dy) {
    kint ny = y + dy;
    if (ny < 0 || ny >= p->height) continue;
    for (kint dx = -1; dx <= 1; ++dx) {
      kint nx = x + dx;
      if ((dx == 0 && dy == 0) || nx < 0 || nx >= p->width) continue;
      kint f = ny * p->width + nx;
      float ex = fresh->motion[2 * f] - mx, ey = fresh->motion[2 * f + 1] - my;
      if (ex * ex + ey * ey > K_REPROJECT_FOOTPRINT_MOTION * K_REPROJECT_FOOTPRINT_MOTION) continue;
      if (k_reproject_tap_matches(p, history, q, fresh->id[f], fresh->prev_depth[f], v3_load_g(fresh->normal + 3 * f)))
        return 1;
    }
  }
  return 0;
}

KFN void k_reproject_pixel(const KReprojectParams* p, const KReprojectFresh* fresh, const KReprojectHistory* history,
                           const KReprojectState* next, kint x, kint y) {
  kint pix = y * p->width + x;
  next->depth[pix] = fresh->depth[pix];
  next->id[pix] = fresh->id[pix];
  next->normal[3 * pix] = fresh->normal[3 * pix];
  next->normal[3 * pix + 1] = fresh->normal[3 * pix + 1];
  next->normal[3 * pix + 2] = fresh->normal[3 * pix + 2];

  /* The history, reprojected: bilinear over the taps that saw the same surface. */
  KVec3 h = v3s(0.0f);
  float history_length = 0.0f;
  float h1 = 0.0f, h2 = 0.0f; /* the history's luminance moments */
  float mx = fresh->motion[2 * pix], my = fresh->motion[2 * pix + 1];
  int moved = k_fabs(mx) > p->still_motion || k_fabs(my) > p->still_motion;
  if (p->have_history && k_fabs(mx) < 1e8f) {
    float hx = (float)x + mx, hy = (float)y + my; /* pixel-centre space */
    float fx = k_floor(hx), fy = k_floor(hy);
    float wx = hx - fx, wy = hy - fy;
    kint x0 = (kint)fx, y0 = (kint)fy;
    kuint id = fresh->id[pix];
    float expected_depth = fresh->prev_depth[pix];
    KVec3 n = v3_load_g(fresh->normal + 3 * pix);
    float weight_sum = 0.0f, length_sum = 0.0f;
    int other_surface = 0; /* bit t: tap t holds history of another surface than this sample's */
    /* Pass 0: the taps that saw this sample's surface; pass 1 (footprint_taps, above): others in its footprint. */
    for (int pass = 0; pass < 2; ++pass) {
      if (pass == 1 && !(p->footprint_taps && other_surface && weight_sum < K_REPROJECT_FOOTPRINT_SHARE)) break;
      for (int t = 0; t < 4; ++t) {
        kint tx = x0 + (t & 1), ty = y0 + (t >> 1);
        float w = ((t & 1) ? wx : 1.0f - wx) * ((t >> 1) ? wy : 1.0f - wy);
        if (w <= 0.0f || tx < 0 || ty < 0 || tx >= p->width || ty >= p->height) continue;
        kint q = ty * p->width + tx;
        if (!(history->length[q] > 0.0f)) continue;
        if (pass == 0) {
          if (!k_reproject_tap_matches(p, history, q, id, expected_depth, n)) {
            other_surface |= 1 << t;
            continue;
          }
        } else if (!(other_surface & (1 << t)) || !k_reproject_footprint_tap(p, fresh, history, q, x, y, mx, my)) {
          continue;
        }
        KFloat4 c = k_load4(history->rgba + 4 * q);
        h = v3_madd(h, v3(c.x, c.y, c.z), w);
        length_sum += w * history->length[q];
        weight_sum += w;
        if (p->moments) {
          h1 += w * history->moments[2 * q];
          h2 += w * history->moments[2 * q + 1];
        }
      }
    }
    if (weight_sum > 1e-3f) {
      float inv = 1.0f / weight_sum;
      h = v3_scale(h, inv);
      history_length = length_sum * inv;
      h1 *= inv;
      h2 *= inv;
    }
  }
  if (history_length > 0.0f && moved && p->anti_lag_sigma > 0.0f)
    history_length *= k_reproject_anti_lag(p, fresh, history, x, y, (float)x + mx, (float)y + my);
  KVec3 m1, m2;
  if (history_length > 0.0f && moved) {
    int count = k_reproject_moments(p, fresh->ycocgw, x, y, &m1, &m2);
    if (count > 0) {
      float inv = 1.0f / (float)count;
      KVec3 mean = v3_scale(m1, inv);
      KVec3 var = v3_sub(v3_scale(m2, inv), v3_mul(mean, mean));
      KVec3 sigma = v3(k_sqrt(k_fmax(var.x, 0.0f)), k_sqrt(k_fmax(var.y, 0.0f)), k_sqrt(k_fmax(var.z, 0.0f)));
      KVec3 lo = v3_madd(mean, sigma, -p->clamp_sigma), hi = v3_madd(mean, sigma, p->clamp_sigma);
      KVec3 v = k_reproject_to_ycocg(h);
      v = v3_min(v3_max(v, lo), hi);
      h = k_reproject_from_ycocg(v);
    }
  }
  KGLOBAL const float* sample = fresh->rgba + 4 * pix;
  KGLOBAL float* out = next->rgba + 4 * pix;
  out[3] = 1.0f;
  if (fresh->ycocgw[4 * pix + 3] != 0.0f) {
    float count = k_fmin(history_length + 1.0f, p->max_history);
    float f = history_length > 0.0f ? 1.0f / count : 1.0f;
    out[0] = h.x + f * (sample[0] - h.x);
    out[1] = h.y + f * (sample[1] - h.y);
    out[2] = h.z + f * (sample[2] - h.z);
    next->length[pix] = history_length > 0.0f ? count : 1.0f;
    if (p->moments) {
      /* A finite sample over a dark albedo can still overflow l^2: such a sample stays out of them. */
      float l = k_illumination_luminance(fresh->rgba, fresh->albedo, pix);
      float fl = k_fabs(l) < 1e18f ? f : 0.0f;
      if (!(fl > 0.0f)) l = 0.0f;
      next->moments[2 * pix] = h1 + fl * (l - h1);
      next->moments[2 * pix + 1] = h2 + fl * (l * l - h2);
    }
  } else if (history_length > 0.0f) {
    out[0] = h.x; out[1] = h.y; out[2] = h.z;
    next->length[pix] = history_length;
    if (p->moments) {
      next->moments[2 * pix] = h1;
      next->moments[2 * pix + 1] = h2;
    }
  } else {
    /* No usable sample and no history: show the neighbourhood's mean, keep no history. */
    int count = k_reproject_moments(p, fresh->ycocgw, x, y, &m1, &m2);
    KVec3 mean = v3_scale(m1, count > 0 ? 1.0f / (float)count : 0.0f);
    KVec3 c = k_reproject_from_ycocg(mean);
    out[0] = c.x; out[1] = c.y; out[2] = c.z;
    next->length[pix] = 0.0f;
    if (p->moments) {
      next->moments[2 * pix] = 0.0f;
      next->moments[2 * pix + 1] = 0.0f;
    }
  }
}

#endif
