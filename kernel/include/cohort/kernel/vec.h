/* Three-component vector maths on a plain struct. OpenCL's float3 is 16 bytes and CUDA's float3 is
 * 12, so the kernel uses its own 12-byte type everywhere data crosses a boundary. */
#ifndef COHORT_KERNEL_VEC_H
#define COHORT_KERNEL_VEC_H
#include "portable.h"

typedef struct KVec3 { float x, y, z; } KVec3;

KFN KVec3 v3(float x, float y, float z) { KVec3 r; r.x = x; r.y = y; r.z = z; return r; }
KFN KVec3 v3s(float s) { return v3(s, s, s); }
KFN KVec3 v3_load(const float* p) { return v3(p[0], p[1], p[2]); }
KFN KVec3 v3_load_g(KGLOBAL const float* p) { return v3(p[0], p[1], p[2]); }
KFN KVec3 v3_add(KVec3 a, KVec3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
KFN KVec3 v3_sub(KVec3 a, KVec3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
KFN KVec3 v3_mul(KVec3 a, KVec3 b) { return v3(a.x * b.x, a.y * b.y, a.z * b.z); }
KFN KVec3 v3_scale(KVec3 a, float s) { return v3(a.x * s, a.y * s, a.z * s); }
KFN KVec3 v3_madd(KVec3 a, KVec3 b, float s) { return v3(a.x + b.x * s, a.y + b.y * s, a.z + b.z * s); }
KFN KVec3 v3_neg(KVec3 a) { return v3(-a.x, -a.y, -a.z); }
KFN float v3_dot(KVec3 a, KVec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
KFN KVec3 v3_cross(KVec3 a, KVec3 b) {
  return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
/* Whether three floats are all finite (no NaN, no infinity), without isfinite: fast-math builds may fold it. */
KFN int k_finite3(float r, float g, float b) {
  return r == r && g == g && b == b && k_fabs(r) <= 3.0e38f && k_fabs(g) <= 3.0e38f && k_fabs(b) <= 3.0e38f;
}
KFN float v3_length(KVec3 a) { return k_sqrt(v3_dot(a, a)); }
KFN KVec3 v3_normalize(KVec3 a) {
  float l = v3_length(a);
  return l > 0.0f ? v3_scale(a, 1.0f / l) : v3(0.0f, 0.0f, 1.0f);
}
KFN KVec3 v3_min(KVec3 a, KVec3 b) { return v3(k_fmin(a.x, b.x), k_fmin(a.y, b.y), k_fmin(a.z, b.z)); }
KFN KVec3 v3_max(KVec3 a, KVec3 b) { return v3(k_fmax(a.x, b.x), k_fmax(a.y, b.y), k_fmax(a.z, b.z)); }
KFN float v3_max_component(KVec3 a) { return k_fmax(a.x, k_fmax(a.y, a.z)); }
KFN float v3_luminance(KVec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

/* 3x4 row-major affine transform: rows are (r0 r1 r2 | t). */
KFN KVec3 xform_point_g(KGLOBAL const float* m, KVec3 p) {
  return v3(m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3],
            m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
            m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]);
}
KFN KVec3 xform_vector_g(KGLOBAL const float* m, KVec3 v) {
  return v3(m[0] * v.x + m[1] * v.y + m[2] * v.z,
            m[4] * v.x + m[5] * v.y + m[6] * v.z,
            m[8] * v.x + m[9] * v.y + m[10] * v.z);
}
/* Normals go through the transpose of the inverse: with world_to_object that is its transpose. */
KFN KVec3 xform_normal_by_inverse_g(KGLOBAL const float* inv, KVec3 n) {
  return v3(inv[0] * n.x + inv[4] * n.y + inv[8] * n.z,
            inv[1] * n.x + inv[5] * n.y + inv[9] * n.z,
            inv[2] * n.x + inv[6] * n.y + inv[10] * n.z);
}

#endif
