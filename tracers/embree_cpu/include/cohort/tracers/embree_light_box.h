// Whether a light tree node's box holds a point (kernel/light_tree.h's K_LIGHT_NODE_HOLDS hook) in SSE for the
// CPU: both corners compared on three axes at once, one branch on the mask, where the scalar test's six
// compare-and-branch steps mispredict at whichever axis the point leaves the box. The same comparisons (NaN:
// outside). Included before the kernel headers (embree_kernel.h); elsewhere the portable test stays.
#pragma once

#if defined(__SSE2__) || defined(_M_X64)
#include <emmintrin.h>

namespace cohort::tracers::embree_light_box {

// box: a KLightNode's first eight floats (bmin[3], left_first, bmax[3], count); the fourth lanes are not compared.
static inline int holds(const float* box, float x, float y, float z) {
  const __m128 p = _mm_setr_ps(x, y, z, 0.0f);
  const __m128 inside = _mm_and_ps(_mm_cmpge_ps(p, _mm_loadu_ps(box)), _mm_cmple_ps(p, _mm_loadu_ps(box + 4)));
  return (_mm_movemask_ps(inside) & 7) == 7;
}

}  // namespace cohort::tracers::embree_light_box

#define K_LIGHT_NODE_HOLDS(n, p) cohort::tracers::embree_light_box::holds((n)->bmin, (p).x, (p).y, (p).z)
#endif
