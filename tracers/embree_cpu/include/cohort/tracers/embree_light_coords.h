// Where a point lies in a Doom 3 light's volume (kernel/lights.h's K_LIGHT_COORDS hook) in SSE for the CPU: the
// four plane evaluations (S, T, Q, F) as one transposed 4x4 product, the projected light's division by Q on
// two lanes, and the three [0, 1] tests as one mask, where the scalar test's compare-and-branch steps mispredict
// at whichever coordinate leaves the volume (the in-range light pick asks it of every light whose tree box
// holds the point, most of them outside). Per lane the same operations in the same order as the portable
// k_light_coords, so the same answer and, inside, the same S, T and F (EmbreeLightCoords.*). Included before the
// kernel headers (embree_kernel.h); elsewhere the portable function stays.
#pragma once

#if defined(__SSE2__) || defined(_M_X64)
#include <xmmintrin.h>

namespace cohort::tracers::embree_light_coords {

// planes: a KLight's plane_s, plane_t, plane_q, plane_f (16 floats in that order); projected: its type is
// K_LIGHT_PROJECTED. 1 when (x, y, z) lies inside, with *s, *t, *f; 0 outside (*s, *t, *f then unspecified).
static inline int coords(const float* planes, int projected, float x, float y, float z, float* s, float* t,
                         float* f) {
  __m128 c0 = _mm_loadu_ps(planes), c1 = _mm_loadu_ps(planes + 4), c2 = _mm_loadu_ps(planes + 8),
         c3 = _mm_loadu_ps(planes + 12);
  _MM_TRANSPOSE4_PS(c0, c1, c2, c3);  // c0: every plane's x coefficient, in the order S, T, Q, F
  __m128 v = _mm_add_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(c0, _mm_set1_ps(x)), _mm_mul_ps(c1, _mm_set1_ps(y))),
                                   _mm_mul_ps(c2, _mm_set1_ps(z))),
                        c3);
  if (projected) {
    const float q = _mm_cvtss_f32(_mm_shuffle_ps(v, v, _MM_SHUFFLE(2, 2, 2, 2)));
    if (q <= 0.0f) return 0;
    v = _mm_div_ps(v, _mm_setr_ps(q, q, 1.0f, 1.0f));  // F over 1: itself, bit for bit
  }
  const __m128 inside = _mm_and_ps(_mm_cmpge_ps(v, _mm_setzero_ps()), _mm_cmple_ps(v, _mm_set1_ps(1.0f)));
  *s = _mm_cvtss_f32(v);
  *t = _mm_cvtss_f32(_mm_shuffle_ps(v, v, _MM_SHUFFLE(1, 1, 1, 1)));
  *f = _mm_cvtss_f32(_mm_shuffle_ps(v, v, _MM_SHUFFLE(3, 3, 3, 3)));
  return (_mm_movemask_ps(inside) & 0xB) == 0xB;  // S, T and F; not Q
}

}  // namespace cohort::tracers::embree_light_coords

#define K_LIGHT_COORDS(light, p, s, t, f)                                                                          \
  cohort::tracers::embree_light_coords::coords((light)->plane_s, (light)->type == K_LIGHT_PROJECTED, (p).x, (p).y, \
                                               (p).z, s, t, f)
#endif
