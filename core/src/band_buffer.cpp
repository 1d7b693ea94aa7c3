#include "cohort/core/band_buffer.h"

#include <algorithm>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "cohort/core/half_float.h"
#include "cohort/kernel/band_pack.h"

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace cohort::core {

const char* to_string(BandFormat format) {
  switch (format) {
    case BandFormat::rgb16f: return "rgb16f";
    case BandFormat::rgb9e5: return "rgb9e5";
    case BandFormat::rgba32f: break;
  }
  return "rgba32f";
}

BandFormat band_format_from_string(const std::string& name) {
  for (BandFormat format : {BandFormat::rgba32f, BandFormat::rgb16f, BandFormat::rgb9e5})
    if (name == to_string(format)) return format;
  throw std::invalid_argument("unknown band format '" + name + "' (rgba32f, rgb16f or rgb9e5)");
}

size_t bytes_per_pixel(BandFormat format) {
  switch (format) {
    case BandFormat::rgb16f: return 3 * sizeof(uint16_t);
    case BandFormat::rgb9e5: return sizeof(uint32_t);
    case BandFormat::rgba32f: break;
  }
  return 4 * sizeof(float);
}

void rgba32f_to_rgb9e5(const float* rgba, uint32_t* packed, size_t pixels, uint32_t first_pixel, uint32_t frame) {
  for (size_t p = 0; p < pixels; ++p) {
    const float dither = k_rgb9e5_dither(first_pixel + static_cast<uint32_t>(p), frame);
    packed[p] = k_rgb9e5_encode(rgba[4 * p + 0], rgba[4 * p + 1], rgba[4 * p + 2], dither);
  }
}

// k_rgb9e5_channel's arithmetic written as selects on bits, so that GCC vectorises the loop (the merge
// decodes every remote and GPU row of a frame on the host).
void rgb9e5_to_rgba32f(const uint32_t* __restrict packed, float* __restrict rgba, size_t pixels) {
  for (size_t p = 0; p < pixels; ++p) {
    const uint32_t word = packed[p];
    float scale;
    const uint32_t scale_bits = ((word >> 27) + 103u) << 23;
    std::memcpy(&scale, &scale_bits, sizeof scale);
    const bool nonfinite = word == K_RGB9E5_NONFINITE;
    for (uint32_t k = 0; k < 3; ++k) {
      const float value = static_cast<float>((word >> (9u * k)) & 511u) * scale;
      rgba[4 * p + k] = nonfinite ? std::numeric_limits<float>::quiet_NaN() : value;
    }
    rgba[4 * p + 3] = 1.0f;
  }
}

namespace {

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define COHORT_F16C_DISPATCH 1
// With F16C (every x86-64 CPU since 2012) a pixel is one conversion instruction each way. Chosen at
// run time, so the build needs no -march.
bool have_f16c() {
  static const bool yes = __builtin_cpu_supports("f16c") && __builtin_cpu_supports("sse4.1");
  return yes;
}

__attribute__((target("f16c,sse4.1"))) void rgb16f_to_rgba32f_f16c(const uint16_t* rgb, float* rgba, size_t pixels) {
  const __m128 one = _mm_set1_ps(1.0f);
  size_t p = 0;
  for (; p + 1 < pixels; ++p) {  // an 8-byte load takes the next pixel's red too: not for the last pixel
    const __m128i halves = _mm_loadl_epi64(reinterpret_cast<const __m128i*>(rgb + 3 * p));
    _mm_storeu_ps(rgba + 4 * p, _mm_blend_ps(_mm_cvtph_ps(halves), one, 0x8));
  }
  for (; p < pixels; ++p) {
    for (size_t k = 0; k < 3; ++k) rgba[4 * p + k] = half_to_float(rgb[3 * p + k]);
    rgba[4 * p + 3] = 1.0f;
  }
}

__attribute__((target("f16c,sse4.1"))) void rgba32f_to_rgb16f_f16c(const float* rgba, uint16_t* rgb, size_t pixels) {
  size_t p = 0;
  for (; p + 1 < pixels; ++p) {  // an 8-byte store runs into the next pixel's red, which comes next
    const __m128i halves = _mm_cvtps_ph(_mm_loadu_ps(rgba + 4 * p), _MM_FROUND_TO_NEAREST_INT);
    _mm_storel_epi64(reinterpret_cast<__m128i*>(rgb + 3 * p), halves);
  }
  for (; p < pixels; ++p)
    for (size_t k = 0; k < 3; ++k) rgb[3 * p + k] = float_to_half(rgba[4 * p + k]);
}
#endif

// Every channel converted in one contiguous loop (GCC vectorises it; picking 3 of 4 channels in the
// same loop it does not), then packed to RGB.
void rgba32f_to_rgb16f_chunk(const float* __restrict rgba, uint16_t* __restrict rgb, size_t pixels) {
  uint16_t halves[4 * 256];
  for (size_t i = 0; i < 4 * pixels; ++i) halves[i] = float_to_half(rgba[i]);
  for (size_t p = 0; p < pixels; ++p) {
    rgb[3 * p + 0] = halves[4 * p + 0];
    rgb[3 * p + 1] = halves[4 * p + 1];
    rgb[3 * p + 2] = halves[4 * p + 2];
  }
}

}  // namespace

// Plain loops over restrict pointers: GCC vectorises the conversions at -O3 (-fopt-info-vec says so).
void rgba32f_to_rgb16f(const float* __restrict rgba, uint16_t* __restrict rgb, size_t pixels) {
#ifdef COHORT_F16C_DISPATCH
  if (have_f16c()) return rgba32f_to_rgb16f_f16c(rgba, rgb, pixels);
#endif
  constexpr size_t kChunk = 256;
  for (size_t p = 0; p < pixels; p += kChunk)
    rgba32f_to_rgb16f_chunk(rgba + 4 * p, rgb + 3 * p, std::min(kChunk, pixels - p));
}

void rgb16f_to_rgba32f(const uint16_t* __restrict rgb, float* __restrict rgba, size_t pixels) {
#ifdef COHORT_F16C_DISPATCH
  if (have_f16c()) return rgb16f_to_rgba32f_f16c(rgb, rgba, pixels);
#endif
  for (size_t p = 0; p < pixels; ++p) {
    rgba[4 * p + 0] = half_to_float(rgb[3 * p + 0]);
    rgba[4 * p + 1] = half_to_float(rgb[3 * p + 1]);
    rgba[4 * p + 2] = half_to_float(rgb[3 * p + 2]);
    rgba[4 * p + 3] = 1.0f;
  }
}

void BandBuffer::resize(int width, int height, BandFormat format) {
  if (width < 0 || height < 0) throw std::invalid_argument("BandBuffer: negative size");
  if (width == width_ && height == height_ && format == format_) return;
  width_ = width;
  height_ = height;
  format_ = format;
  storage_.assign(static_cast<size_t>(width) * static_cast<size_t>(height) * bytes_per_pixel(format), 0);
  if (!aux_.empty()) aux_.assign(static_cast<size_t>(width) * static_cast<size_t>(height), AuxTexel{});
}

void BandBuffer::enable_aux(bool on) {
  const size_t pixels = static_cast<size_t>(width_) * static_cast<size_t>(height_);
  if (!on) std::vector<AuxTexel>().swap(aux_);
  else if (aux_.size() != pixels) aux_.assign(pixels, AuxTexel{});
}

void BandBuffer::store_aux(int y, int x, const KAux* aux, size_t pixels) {
  if (aux_.empty()) throw std::logic_error("BandBuffer::store_aux: aux planes are not enabled");
  if (y < 0 || y >= height_ || x < 0 || static_cast<size_t>(x) + pixels > static_cast<size_t>(width_))
    throw std::out_of_range("BandBuffer::store_aux: pixels outside the buffer");
  AuxTexel* to = aux_.data() + static_cast<size_t>(y) * static_cast<size_t>(width_) + static_cast<size_t>(x);
  for (size_t p = 0; p < pixels; ++p) {
    const KAux& a = aux[p];
    AuxTexel& t = to[p];
    t.depth = a.depth;
    t.prev_depth = a.prev_depth;
    t.motion[0] = a.motion[0];
    t.motion[1] = a.motion[1];
    for (int k = 0; k < 3; ++k) {
      t.normal[k] = float_to_half(a.normal[k]);
      t.albedo[k] = float_to_half(a.albedo[k]);
    }
    t.id = a.id;
  }
}

void BandBuffer::copy_aux_rows_to(GBuffer& out, int row_begin, int row_end) const {
  if (aux_.empty()) throw std::logic_error("BandBuffer::copy_aux_rows_to: aux planes are not enabled");
  if (out.width != width_ || out.height != height_) throw std::invalid_argument("BandBuffer::copy_aux_rows_to: size mismatch");
  if (row_begin < 0 || row_end > height_ || row_begin > row_end) throw std::out_of_range("BandBuffer::copy_aux_rows_to: rows");
  const size_t first = static_cast<size_t>(row_begin) * static_cast<size_t>(width_);
  const size_t last = static_cast<size_t>(row_end) * static_cast<size_t>(width_);
  for (size_t i = first; i < last; ++i) {
    const AuxTexel& t = aux_[i];
    out.depth[i] = t.depth;
    out.prev_depth[i] = t.prev_depth;
    out.motion[2 * i] = t.motion[0];
    out.motion[2 * i + 1] = t.motion[1];
    for (size_t k = 0; k < 3; ++k) {
      out.normal[3 * i + k] = half_to_float(t.normal[k]);
      out.albedo[3 * i + k] = half_to_float(t.albedo[k]);
    }
    out.id[i] = t.id;
  }
}

void BandBuffer::store(int y, int x, const float* rgba, size_t pixels, uint32_t frame) {
  if (y < 0 || y >= height_ || x < 0 || static_cast<size_t>(x) + pixels > static_cast<size_t>(width_))
    throw std::out_of_range("BandBuffer::store: pixels outside the buffer");
  unsigned char* at = static_cast<unsigned char*>(row(y)) + static_cast<size_t>(x) * bytes_per_pixel(format_);
  if (format_ == BandFormat::rgba32f) std::memcpy(at, rgba, pixels * 4 * sizeof(float));
  else if (format_ == BandFormat::rgb16f) rgba32f_to_rgb16f(rgba, reinterpret_cast<uint16_t*>(at), pixels);
  else
    rgba32f_to_rgb9e5(rgba, reinterpret_cast<uint32_t*>(at), pixels,
                      static_cast<uint32_t>(y) * static_cast<uint32_t>(width_) + static_cast<uint32_t>(x), frame);
}

void BandBuffer::copy_rows_to(FrameBuffer& out, int row_begin, int row_end) const {
  if (out.width != width_ || out.height != height_) throw std::invalid_argument("BandBuffer::copy_rows_to: size mismatch");
  if (row_begin < 0 || row_end > height_ || row_begin > row_end) throw std::out_of_range("BandBuffer::copy_rows_to: rows");
  const size_t pixels = static_cast<size_t>(width_) * static_cast<size_t>(row_end - row_begin);
  float* to = out.row(row_begin);
  if (format_ == BandFormat::rgba32f) std::memcpy(to, row(row_begin), pixels * 4 * sizeof(float));
  else if (format_ == BandFormat::rgb16f) rgb16f_to_rgba32f(static_cast<const uint16_t*>(row(row_begin)), to, pixels);
  else rgb9e5_to_rgba32f(static_cast<const uint32_t*>(row(row_begin)), to, pixels);
}

void BandBuffer::copy_rows_from(const BandBuffer& from, int row_begin, int row_end) {
  if (from.width_ != width_ || from.height_ != height_ || from.format_ != format_)
    throw std::invalid_argument("BandBuffer::copy_rows_from: size or format mismatch");
  if (row_begin < 0 || row_end > height_ || row_begin > row_end) throw std::out_of_range("BandBuffer::copy_rows_from: rows");
  const size_t rows = static_cast<size_t>(row_end - row_begin);
  std::memcpy(row(row_begin), from.row(row_begin), rows * row_bytes());
  if (!aux_.empty() && !from.aux_.empty())
    std::memcpy(aux_row(row_begin), from.aux_.data() + static_cast<size_t>(row_begin) * static_cast<size_t>(width_),
                rows * static_cast<size_t>(width_) * sizeof(AuxTexel));
}

}  // namespace cohort::core
