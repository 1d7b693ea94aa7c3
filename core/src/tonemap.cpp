#include "cohort/core/tonemap.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "cohort/core/host_threads.h"

namespace cohort::core {

namespace {

constexpr size_t kPixelsPerRange = 16384;  // smaller ranges cost more to hand out than they save

float hable(float x) {
  // Hable's published constants: shoulder, linear, toe strengths and angles.
  constexpr float A = 0.15f, B = 0.50f, C = 0.10f, D = 0.20f, E = 0.02f, F = 0.30f;
  return ((x * (A * x + C * B) + D * E) / (x * (A * x + B) + D * F)) - E / F;
}

// Linear display value -> byte, in 2^16 steps: pow() per channel would dominate, and a coarser table
// would band the darks, where gamma encoding is steepest.
constexpr int kEncodeSteps = 65535;

const std::vector<uint8_t>& encode_table(bool srgb) {
  static const auto build = [](bool s) {
    std::vector<uint8_t> t(kEncodeSteps + 1);
    for (int i = 0; i <= kEncodeSteps; ++i)
      t[static_cast<size_t>(i)] = static_cast<uint8_t>(std::lround(255.0f * encode_display(static_cast<float>(i) / kEncodeSteps, s)));
    return t;
  };
  static const std::vector<uint8_t> gamma22 = build(false), srgb_curve = build(true);
  return srgb ? srgb_curve : gamma22;
}

// apply_tone_curve for one curve, without branches: NaN and negatives go to 0 and huge values (and
// infinity) to the top through the clamps, as there.
template <ToneCurve Curve>
inline float curve_value(float x, float white_point) {
  x = std::min(x > 0.0f ? x : 0.0f, 1e15f);  // NaN fails x > 0; 1e15 keeps every curve's squares finite
  float y;
  if constexpr (Curve == ToneCurve::gamma) {
    y = x;
  } else if constexpr (Curve == ToneCurve::reinhard) {
    y = white_point > 0.0f ? x * (1.0f + x / (white_point * white_point)) / (1.0f + x) : x / (1.0f + x);
  } else if constexpr (Curve == ToneCurve::aces) {
    y = (x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f);
  } else {
    const float white = white_point > 0.0f ? white_point : 11.2f;
    y = hable(2.0f * x) / hable(white);  // Hable's curve is tuned for inputs pre-scaled by 2
  }
  return std::min(std::max(y, 0.0f), 1.0f);
}

// The table path over pixels [begin, end) in chunks: the curve over every channel in one contiguous
// loop (vectorised), then the table look-ups.
template <ToneCurve Curve>
void table_tone_map(const FrameBuffer& frame, size_t begin, size_t end, float scale, float white,
                    const std::vector<uint8_t>& encode, std::vector<uint8_t>& out) {
  constexpr size_t kChunk = 512;
  float curved[4 * kChunk];
  for (size_t chunk = begin; chunk < end; chunk += kChunk) {
    const size_t n = std::min(kChunk, end - chunk);
    const float* __restrict in = frame.rgba.data() + 4 * chunk;
    for (size_t i = 0; i < 4 * n; ++i) curved[i] = curve_value<Curve>(in[i] * scale, white) * kEncodeSteps + 0.5f;
    uint8_t* __restrict bytes = out.data() + 4 * chunk;
    for (size_t p = 0; p < n; ++p) {
      for (size_t k = 0; k < 3; ++k) bytes[4 * p + k] = encode[static_cast<size_t>(curved[4 * p + k])];
      bytes[4 * p + 3] = 255;
    }
  }
}

}  // namespace

ToneCurve parse_tone_curve(std::string_view name) {
  if (name == "gamma") return ToneCurve::gamma;
  if (name == "reinhard") return ToneCurve::reinhard;
  if (name == "aces") return ToneCurve::aces;
  if (name == "uncharted2" || name == "filmic") return ToneCurve::uncharted2;
  throw std::invalid_argument("unknown tone curve '" + std::string(name) + "' (known: gamma, reinhard, aces, uncharted2)");
}

const char* to_string(ToneCurve curve) {
  switch (curve) {
    case ToneCurve::gamma: return "gamma";
    case ToneCurve::reinhard: return "reinhard";
    case ToneCurve::aces: return "aces";
    case ToneCurve::uncharted2: return "uncharted2";
  }
  return "unknown";
}

float apply_tone_curve(ToneCurve curve, float x, float white_point) {
  if (!(x > 0.0f)) return 0.0f;  // negatives and NaN
  if (std::isinf(x)) return 1.0f;
  float y = 0.0f;
  switch (curve) {
    case ToneCurve::gamma: y = x; break;
    case ToneCurve::reinhard:
      y = white_point > 0.0f ? x * (1.0f + x / (white_point * white_point)) / (1.0f + x) : x / (1.0f + x);
      break;
    case ToneCurve::aces: y = (x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f); break;
    case ToneCurve::uncharted2: {
      const float white = white_point > 0.0f ? white_point : 11.2f;
      constexpr float kExposureBias = 2.0f;  // Hable's curve is tuned for inputs pre-scaled by 2
      y = hable(kExposureBias * x) / hable(white);
      break;
    }
  }
  return std::clamp(y, 0.0f, 1.0f);
}

float encode_display(float linear, bool srgb) {
  const float x = std::clamp(linear, 0.0f, 1.0f);
  if (!srgb) return std::pow(x, 1.0f / 2.2f);
  return x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1.0f / 2.4f) - 0.055f;
}

std::vector<uint8_t> tone_map(const FrameBuffer& frame, const ToneMapOptions& options) {
  const size_t pixels = static_cast<size_t>(frame.width) * frame.height;
  if (frame.rgba.size() != pixels * 4) throw std::invalid_argument("tone_map: frame buffer size mismatch");
  const float scale = static_cast<float>(std::exp2(options.exposure_ev));
  const float white = static_cast<float>(options.white_point);
  const std::vector<uint8_t>& encode = encode_table(options.srgb);
  std::vector<uint8_t> out(pixels * 4);
  if (!options.exact_encoding) {
    HostThreads::shared().for_ranges(pixels, kPixelsPerRange, [&](size_t begin, size_t end) {
      switch (options.curve) {
        case ToneCurve::gamma: table_tone_map<ToneCurve::gamma>(frame, begin, end, scale, white, encode, out); break;
        case ToneCurve::reinhard: table_tone_map<ToneCurve::reinhard>(frame, begin, end, scale, white, encode, out); break;
        case ToneCurve::aces: table_tone_map<ToneCurve::aces>(frame, begin, end, scale, white, encode, out); break;
        case ToneCurve::uncharted2: table_tone_map<ToneCurve::uncharted2>(frame, begin, end, scale, white, encode, out); break;
      }
    });
    return out;
  }
  HostThreads::shared().for_ranges(pixels, kPixelsPerRange, [&](size_t begin, size_t end) {
    for (size_t p = begin; p < end; ++p) {
      for (int k = 0; k < 3; ++k) {
        const size_t i = p * 4 + static_cast<size_t>(k);
        const float v = std::isfinite(frame.rgba[i]) ? frame.rgba[i] : 0.0f;
        const float encoded = encode_display(apply_tone_curve(options.curve, v * scale, white), options.srgb);
        out[i] = static_cast<uint8_t>(encoded * 255.0f + 0.5f);
      }
      out[p * 4 + 3] = 255;
    }
  });
  return out;
}

}  // namespace cohort::core
