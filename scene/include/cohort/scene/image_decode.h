// Decoding image files to RGBA8: through OpenImageIO when built with it (TGA, PNG, JPEG, DDS, ...),
// with a built-in TGA reader always available so the build without OpenImageIO still loads TGA maps.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "cohort/scene/scene.h"

namespace cohort::scene {

// Images larger than this many pixels are refused rather than allocated.
constexpr long long kMaxImagePixels = 64ll << 20;

// `file_name` supplies the extension that picks the format. On failure returns nothing and says why.
std::optional<Image> decode_image(std::string_view bytes, const std::string& file_name, std::string& error);

// Uncompressed and run-length-encoded true-colour and grey TGA (8/16/24/32 bits), either row order.
std::optional<Image> decode_tga(std::string_view bytes, std::string& error);

// A DDS whose header names the "RXGB" swizzle (Doom 3 normal maps: X stored in alpha).
bool is_rxgb_dds(std::string_view bytes);

}  // namespace cohort::scene
