// A 5x7 pixel font for chart labels (upper case; lower case is drawn as upper case).
#pragma once

#include <array>
#include <cstdint>

namespace cohort::app {

// Rows top to bottom, bit 4 = leftmost column; all zero for characters it does not know.
std::array<uint8_t, 7> glyph(char c);
constexpr int kGlyphWidth = 5, kGlyphHeight = 7;

}  // namespace cohort::app
