// HDR linear frame -> 8-bit display RGBA: exposure, a tone curve, then display encoding (gamma 2.2 or
// the sRGB curve).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "cohort/core/frame_buffer.h"

namespace cohort::core {

enum class ToneCurve {
  gamma,       // clamp to [0, 1]: no curve, only display encoding
  reinhard,    // x / (1 + x), or the extended form with a white point
  aces,        // Narkowicz's fit of the ACES reference rendering + output transform
  uncharted2,  // Hable's filmic curve (Uncharted 2), normalised to a white point
};

struct ToneMapOptions {
  ToneCurve curve = ToneCurve::aces;
  double exposure_ev = 0.0;      // scene values are multiplied by 2^exposure_ev first
  double white_point = 11.2;     // reinhard (extended) and uncharted2: input that maps to 1; <= 0: reinhard is x/(1+x)
  bool srgb = false;             // sRGB transfer curve instead of plain gamma 2.2
  // Encode each value with pow() and round it half up, instead of looking it up in the 2^16-step
  // table: several times slower, and a step off the table's bytes near some byte boundaries (most in
  // the darks). `cohort render` writes its frames this way, so the bytes of its images never depend on
  // the table. Non-finite values (+infinity too) become black.
  bool exact_encoding = false;
};

// "gamma", "reinhard", "aces", "uncharted2"; throws std::invalid_argument listing them otherwise.
ToneCurve parse_tone_curve(std::string_view name);
const char* to_string(ToneCurve curve);

// Linear scene value (after exposure) -> linear display value in [0, 1].
float apply_tone_curve(ToneCurve curve, float x, float white_point);
// Linear display value in [0, 1] -> encoded value in [0, 1].
float encode_display(float linear, bool srgb);

// RGBA8, rows top to bottom; alpha is 255. NaN and negative values become black; +infinity white,
// unless exact_encoding.
std::vector<uint8_t> tone_map(const FrameBuffer& frame, const ToneMapOptions& options);

}  // namespace cohort::core
