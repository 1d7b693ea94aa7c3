// The 5x7 bitmap font the viewer's HUD and the benchmark charts draw with (no font files, no GL text).
// Covers printable ASCII from ' ' to '_' plus '|'; lowercase letters are drawn as capitals, anything
// else as '?'.
#pragma once

namespace cohort::raster {

constexpr int kGlyphWidth = 5;
constexpr int kGlyphHeight = 7;
constexpr int kGlyphAdvance = 6;     // one column of spacing
constexpr int kLineAdvance = 9;      // two rows of spacing

// Whether pixel (x, y) of the glyph for c is set; x in [0,5), y in [0,7) top to bottom.
bool glyph_pixel(char c, int x, int y);

}  // namespace cohort::raster
