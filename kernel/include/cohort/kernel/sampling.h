/* Sampling helpers: orthonormal bases, hemisphere and disk samples. */
#ifndef COHORT_KERNEL_SAMPLING_H
#define COHORT_KERNEL_SAMPLING_H
#include "vec.h"

typedef struct KFrame { KVec3 t, b, n; } KFrame;

/* Branchless basis around a unit normal (Duff et al. 2017). */
KFN KFrame k_frame_from_normal(KVec3 n) {
  float sign = n.z >= 0.0f ? 1.0f : -1.0f;
  float a = -1.0f / (sign + n.z);
  float b = n.x * n.y * a;
  KFrame f;
  f.t = v3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
  f.b = v3(b, sign + n.y * n.y * a, -n.y);
  f.n = n;
  return f;
}

KFN KVec3 k_frame_to_world(const KFrame* f, KVec3 lv) {
  return v3_add(v3_add(v3_scale(f->t, lv.x), v3_scale(f->b, lv.y)), v3_scale(f->n, lv.z));
}

KFN KVec3 k_frame_to_local(const KFrame* f, KVec3 w) {
  return v3(v3_dot(w, f->t), v3_dot(w, f->b), v3_dot(w, f->n));
}

/* Concentric mapping of the unit square onto the unit disk (Shirley-Chiu). */
KFN void k_sample_disk(float u1, float u2, float* dx, float* dy) {
  float a = 2.0f * u1 - 1.0f, b = 2.0f * u2 - 1.0f;
  if (a == 0.0f && b == 0.0f) { *dx = 0.0f; *dy = 0.0f; return; }
  float r, phi;
  if (k_fabs(a) > k_fabs(b)) { r = a; phi = (K_PI / 4.0f) * (b / a); }
  else { r = b; phi = (K_PI / 2.0f) - (K_PI / 4.0f) * (a / b); }
  *dx = r * k_cos(phi);
  *dy = r * k_sin(phi);
}

/* Cosine-weighted direction around +z; pdf = cos(theta) / pi. */
KFN KVec3 k_sample_cosine_hemisphere(float u1, float u2) {
  float dx, dy;
  k_sample_disk(u1, u2, &dx, &dy);
  float z = k_sqrt(k_fmax(0.0f, 1.0f - dx * dx - dy * dy));
  return v3(dx, dy, z);
}

KFN float k_clamp(float x, float lo, float hi) { return k_fmin(k_fmax(x, lo), hi); }
KFN float k_saturate(float x) { return k_clamp(x, 0.0f, 1.0f); }

#endif
