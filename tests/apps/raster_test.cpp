#include "raster/font.h"

#include <set>
#include <string>

#include <gtest/gtest.h>

#include "raster/image.h"

namespace cohort::raster {
namespace {

std::string glyph_rows(char c) {
  std::string s;
  for (int y = 0; y < kGlyphHeight; ++y)
    for (int x = 0; x < kGlyphWidth; ++x) s += glyph_pixel(c, x, y) ? '#' : '.';
  return s;
}

TEST(RasterFont, EveryPrintableGlyphIsDistinctAndSpaceIsBlank) {
  std::set<std::string> seen;
  for (char c = '!'; c <= '_'; ++c) {
    const std::string rows = glyph_rows(c);
    EXPECT_NE(rows.find('#'), std::string::npos) << "glyph '" << c << "' is blank";
    EXPECT_TRUE(seen.insert(rows).second) << "glyph '" << c << "' duplicates another";
  }
  EXPECT_EQ(glyph_rows(' ').find('#'), std::string::npos);
  EXPECT_EQ(glyph_rows('a'), glyph_rows('A'));
  EXPECT_EQ(glyph_rows('\x01'), glyph_rows('?'));
}

TEST(RasterFont, DrawTextSetsPixelsOnlyInsideItsBoxAndClips) {
  Image8 img;
  img.resize(40, 20);
  const int end = draw_text(img, 2, 3, "HI", Rgba8{255, 0, 0, 255}, 1);
  EXPECT_EQ(end, 2 + 2 * kGlyphAdvance);
  int lit = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const uint8_t* p = &img.rgba[(y * img.width + x) * 4];
      if (p[3] == 0) continue;
      ++lit;
      EXPECT_GE(x, 2);
      EXPECT_LT(x, 2 + text_width("HI"));
      EXPECT_GE(y, 3);
      EXPECT_LT(y, 3 + kGlyphHeight);
      EXPECT_EQ(p[0], 255);
    }
  // 'H' has 17 pixels and 'I' 11 in this font.
  EXPECT_EQ(lit, 17 + 11);
  // Drawing off the image must not write out of bounds (ASan checks) nor crash.
  draw_text(img, 38, 18, "WWW", Rgba8{}, 3);
  draw_text(img, -100, -100, "WWW", Rgba8{}, 2);
}

TEST(RasterImage, VerticalTextIsHorizontalTextTurnedCounterClockwise) {
  Image8 across, up;
  across.resize(text_advance("AB2", 2), text_height(2));
  up.resize(text_height(2), text_advance("AB2", 2));
  draw_text(across, 0, 0, "AB2", Rgba8{}, 2);
  draw_text_vertical(up, 0, 0, "AB2", Rgba8{}, 2);
  // (x, y) across lands on (y, height - 1 - x) up.
  for (int y = 0; y < across.height; ++y)
    for (int x = 0; x < across.width; ++x)
      EXPECT_EQ(across.rgba[(static_cast<size_t>(y) * across.width + x) * 4 + 3],
                up.rgba[(static_cast<size_t>(up.height - 1 - x) * up.width + y) * 4 + 3])
          << x << "," << y;
}

TEST(RasterImage, ThickLinesCoverBothEndsAndStayInside) {
  Image8 img;
  img.resize(20, 10);
  draw_line(img, 2, 5, 17, 5, Rgba8{10, 20, 30, 255}, 3);
  auto lit = [&](int x, int y) { return img.rgba[(static_cast<size_t>(y) * img.width + x) * 4 + 3] == 255; };
  for (int x = 0; x < img.width; ++x) EXPECT_EQ(lit(x, 5), x >= 1 && x <= 18) << x;
  EXPECT_TRUE(lit(2, 4) && lit(2, 6) && lit(17, 4) && lit(17, 6));
  EXPECT_FALSE(lit(2, 3) || lit(2, 7) || lit(0, 5) || lit(19, 5));
  draw_line(img, -50, -50, 70, 70, Rgba8{}, 5);  // clipped, no out-of-bounds writes (ASan checks)
}

}  // namespace
}  // namespace cohort::raster
