/* The firefly clamp before the a-trous passes (the anti-firefly step of NVIDIA's NRD denoisers, in spirit): a
 * pixel of the illumination whose luminance exceeds `factor` times the brightest of its 8 neighbours' is
 * scaled down to that. At 1 spp a rare bright path (a light reached through a gap, a glint) makes a pixel far
 * brighter than everything around it; the passes' luminance stop keeps its neighbours from taking its light,
 * so it stays a single bright dot for as long as its short history lasts, which is what the eye (and FLIP)
 * sees after a disocclusion. A feature two pixels wide is left alone: each of its pixels has the other for a
 * neighbour. Only the filter's input is clamped, never the history: the light is lost from the frame shown,
 * not from the frames after (docs/denoising.md, "Fireflies"). Colour planes are RGBA floats; alpha is copied. */
#ifndef COHORT_KERNEL_FIREFLY_H
#define COHORT_KERNEL_FIREFLY_H
#include "illumination.h"
#include "vec.h"

KFN void k_firefly_clamp_pixel(KGLOBAL const float* in_rgba, KGLOBAL float* out_rgba, kint width, kint height,
                               float factor, kint x, kint y) {
  kint centre = y * width + x;
  KFloat4 c = k_load4(in_rgba + 4 * centre);
  float lp = k_luminance3(c.x, c.y, c.z);
  float brightest = 0.0f;
  for (kint dy = -1; dy <= 1; ++dy) {
    kint qy = y + dy;
    if (qy < 0 || qy >= height) continue;
    for (kint dx = -1; dx <= 1; ++dx) {
      kint qx = x + dx;
      if ((dx == 0 && dy == 0) || qx < 0 || qx >= width) continue;
      KFloat4 q = k_load4(in_rgba + 4 * (qy * width + qx));
      if (k_finite3(q.x, q.y, q.z)) brightest = k_fmax(brightest, k_luminance3(q.x, q.y, q.z));
    }
  }
  /* Non-finite pixels pass unchanged (the passes leave them out), as do dark and negative ones. */
  float scale = k_finite3(c.x, c.y, c.z) && lp > factor * brightest && lp > 0.0f ? factor * brightest / lp : 1.0f;
  KGLOBAL float* out = out_rgba + 4 * centre;
  out[0] = c.x * scale;
  out[1] = c.y * scale;
  out[2] = c.z * scale;
  out[3] = c.w;
}

#endif
