// IEEE half floats (binary16) on the host, for bands that travel as RGB16F. Written branch-free (the
// choices are selects), so that the bulk loops over a band vectorise without F16C.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

namespace cohort::core {

namespace half_detail {
inline uint32_t bits(float f) {
  uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return u;
}
inline float from_bits(uint32_t u) {
  float f;
  std::memcpy(&f, &u, sizeof f);
  return f;
}
}  // namespace half_detail

// Round to nearest even; too large gives infinity, NaN stays NaN (F. Giesen's float_to_half_fast3_rtne).
inline uint16_t float_to_half(float value) {
  using namespace half_detail;
  constexpr uint32_t kInfinity = 255u << 23, kHalfOverflow = (127u + 16u) << 23;
  constexpr uint32_t kSubnormalMagic = ((127u - 15u) + (23u - 10u) + 1u) << 23;
  const uint32_t all = bits(value);
  const uint32_t sign = all & 0x80000000u;
  const uint32_t u = all ^ sign;
  const uint32_t special = 0x7c00u | (static_cast<uint32_t>(u > kInfinity) << 9);  // infinity, or a quiet NaN
  // Results below the smallest normal half: align the 10 mantissa bits at the bottom by adding a magic float.
  const uint32_t subnormal = bits(from_bits(u) + from_bits(kSubnormalMagic)) - kSubnormalMagic;
  const uint32_t normal = (u + ((15u - 127u) << 23) + 0xfffu + ((u >> 13) & 1u)) >> 13;
  // Selects as masks rather than ?: so that the compiler keeps a loop of these free of branches.
  const uint32_t is_special = 0u - static_cast<uint32_t>(u >= kHalfOverflow);
  const uint32_t is_subnormal = 0u - static_cast<uint32_t>(u < (113u << 23));
  const uint32_t h = (special & is_special) | (~is_special & ((subnormal & is_subnormal) | (normal & ~is_subnormal)));
  return static_cast<uint16_t>(h | (sign >> 16));
}

inline float half_to_float(uint16_t half) {
  using namespace half_detail;
  const uint32_t sign = static_cast<uint32_t>(half & 0x8000u) << 16;
  const uint32_t magnitude = half & 0x7fffu;
  // Exponent and mantissa moved into a float's place, rescaled by 2^(127-15): right for normals and
  // subnormals alike. An all-ones exponent (infinity, NaN) gets the float's all-ones exponent.
  const uint32_t scaled = bits(from_bits(magnitude << 13) * 0x1p112f);
  return from_bits(scaled | (magnitude >= 0x7c00u ? 0x7f800000u : 0u) | sign);
}

// Bulk conversions between RGBA floats and RGB halves (alpha dropped; read back as 1).
void rgba32f_to_rgb16f(const float* rgba, uint16_t* rgb, size_t pixels);
void rgb16f_to_rgba32f(const uint16_t* rgb, float* rgba, size_t pixels);

}  // namespace cohort::core
