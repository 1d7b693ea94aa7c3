#include "viewer/hud.h"

#include <set>

#include <gtest/gtest.h>

#include "viewer/bitmap_font.h"

namespace cohort::viewer {
namespace {

std::string glyph_rows(char c) {
  std::string s;
  for (int y = 0; y < kGlyphHeight; ++y)
    for (int x = 0; x < kGlyphWidth; ++x) s += glyph_pixel(c, x, y) ? '#' : '.';
  return s;
}

TEST(BitmapFont, EveryPrintableGlyphIsDistinctAndSpaceIsBlank) {
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

TEST(BitmapFont, DrawTextSetsPixelsOnlyInsideItsBoxAndClips) {
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

TEST(Hud, LinesCarryTheFrameStats) {
  HudState s;
  s.fps = 59.9;
  s.mode = "PATH";
  s.spp = 2;
  s.tone_mapper = "aces";
  s.balancer = "perfect-smooth";
  s.commit_bytes = 3 * 1024;
  core::FrameStats stats;
  stats.frame_ms = 16.5;
  stats.idle_percent = 12.5;
  stats.convergence_f = 0.25;
  core::TracerFrameStats t;
  t.name = "embree";
  t.row_begin = 0;
  t.row_end = 120;
  t.ms = 16.5;
  stats.tracers.push_back(t);
  t.name = "opencl:0";
  t.outcome = core::TracerOutcome::timed_out;
  stats.tracers.push_back(t);
  s.stats = stats;
  s.notices.push_back("NO GPU TRACER");
  const std::vector<std::string> lines = hud_lines(s);
  std::string all;
  for (const std::string& l : lines) all += l + "\n";
  EXPECT_NE(all.find("FPS 59.9"), std::string::npos) << all;
  EXPECT_NE(all.find("IDLE 12.5%"), std::string::npos) << all;
  EXPECT_NE(all.find("CONV F 0.25"), std::string::npos) << all;
  EXPECT_NE(all.find("COMMIT 3.0 KB"), std::string::npos) << all;
  EXPECT_NE(all.find("embree"), std::string::npos) << all;
  EXPECT_NE(all.find("timed_out"), std::string::npos) << all;
  EXPECT_EQ(lines.back(), "NO GPU TRACER");

  Image8 layer;
  layer.resize(400, 200);
  draw_hud(layer, s);
  size_t opaque = 0;
  for (size_t i = 3; i < layer.rgba.size(); i += 4) opaque += layer.rgba[i] == 255;
  EXPECT_GT(opaque, 100u);
  EXPECT_EQ(layer.rgba[(199 * 400 + 399) * 4 + 3], 0) << "the corner away from the HUD stays transparent";
}

TEST(Hud, FormatsBytes) {
  EXPECT_EQ(format_bytes(512), "512 B");
  EXPECT_EQ(format_bytes(2048), "2.0 KB");
  EXPECT_EQ(format_bytes(3 * 1024 * 1024), "3.00 MB");
}

}  // namespace
}  // namespace cohort::viewer
