// The bilinear texel read (kernel/texture.h's K_TEXEL_BILINEAR hook) in SSE2 for the CPU: each RGBA8
// texel becomes one float vector (unpack, one conversion, one multiply), the sRGB curve runs on four
// channels at once, and the blend is four multiply-adds. The scalar code spent sixteen int-to-float
// conversions, twelve sRGB polynomials and sixteen multiply-adds per read, the largest block of the
// tracer's profile. Same arithmetic in the same order per channel as texture.h's scalar read.
// Included before the kernel headers (embree_kernel.h); elsewhere the portable read stays.
#pragma once

#if defined(__SSE2__) || defined(_M_X64)
#include <emmintrin.h>

#include <stdint.h>

namespace cohort::tracers::embree_texture {

static inline __m128 texel(const uint32_t* texels, uint32_t index, int srgb) {
  const __m128i zero = _mm_setzero_si128();
  __m128i bytes = _mm_cvtsi32_si128(static_cast<int>(texels[index]));
  __m128i lanes = _mm_unpacklo_epi16(_mm_unpacklo_epi8(bytes, zero), zero);
  __m128 c = _mm_mul_ps(_mm_cvtepi32_ps(lanes), _mm_set1_ps(1.0f / 255.0f));
  if (!srgb) return c;
  // k_srgb_to_linear on r, g, b; alpha stays linear.
  __m128 lin = _mm_mul_ps(c, _mm_add_ps(_mm_mul_ps(c, _mm_add_ps(_mm_mul_ps(c, _mm_set1_ps(0.305306011f)),
                                                                  _mm_set1_ps(0.682171111f))),
                                        _mm_set1_ps(0.012522878f)));
  const __m128 rgb_mask = _mm_castsi128_ps(_mm_set_epi32(0, -1, -1, -1));
  return _mm_or_ps(_mm_and_ps(rgb_mask, lin), _mm_andnot_ps(rgb_mask, c));
}

static inline void bilinear(const uint32_t* texels, uint32_t i00, uint32_t i10, uint32_t i01, uint32_t i11, float ax,
                            float ay, uint32_t srgb, float out[4]) {
  const int s = srgb != 0u;
  const __m128 c00 = texel(texels, i00, s), c10 = texel(texels, i10, s);
  const __m128 c01 = texel(texels, i01, s), c11 = texel(texels, i11, s);
  const float w00 = (1.0f - ax) * (1.0f - ay), w10 = ax * (1.0f - ay), w01 = (1.0f - ax) * ay, w11 = ax * ay;
  __m128 r = _mm_mul_ps(c00, _mm_set1_ps(w00));
  r = _mm_add_ps(r, _mm_mul_ps(c10, _mm_set1_ps(w10)));
  r = _mm_add_ps(r, _mm_mul_ps(c01, _mm_set1_ps(w01)));
  r = _mm_add_ps(r, _mm_mul_ps(c11, _mm_set1_ps(w11)));
  _mm_storeu_ps(out, r);
}

}  // namespace cohort::tracers::embree_texture

#define K_TEXEL_BILINEAR(texels, i00, i10, i01, i11, ax, ay, srgb, out) \
  cohort::tracers::embree_texture::bilinear((texels), (i00), (i10), (i01), (i11), (ax), (ay), (srgb), (out))
#endif
