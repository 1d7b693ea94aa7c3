#include "viewer/hud.h"

#include <gtest/gtest.h>

#include <algorithm>

namespace cohort::viewer {
namespace {

TEST(Hud, LinesCarryTheFrameStats) {
  HudState s;
  s.fps = 59.9;
  s.mode = "PATH";
  s.spp = 2;
  s.tone_mapper = "aces";
  s.balancer = "perfect-smooth";
  s.commit_bytes = 3 * 1024;
  s.accumulation = "REPROJECT+ATROUS ON cuda:0";
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
  EXPECT_NE(all.find("REPROJECT+ATROUS ON cuda:0"), std::string::npos) << all;
  EXPECT_NE(all.find("COMMIT 3.0 KB"), std::string::npos) << all;
  EXPECT_NE(all.find("embree"), std::string::npos) << all;
  EXPECT_NE(all.find("timed_out"), std::string::npos) << all;
  EXPECT_EQ(lines.back(), "NO GPU TRACER");

  raster::Image8 layer;
  layer.resize(400, 200);
  draw_hud(layer, s);
  size_t opaque = 0;
  for (size_t i = 3; i < layer.rgba.size(); i += 4) opaque += layer.rgba[i] == 255;
  EXPECT_GT(opaque, 100u);
  EXPECT_EQ(layer.rgba[(199 * 400 + 399) * 4 + 3], 0) << "the corner away from the HUD stays transparent";
}

// Below scale 1 the HUD says how the frame reaches the window; at scale 1 there is nothing to upsample.
TEST(Hud, NamesTheUpsamplingBelowScaleOne) {
  HudState s;
  s.mode = "PATH";
  s.render_scale = 0.5f;
  s.render_width = 320;
  s.render_height = 180;
  s.target_fps = 30;
  s.upsample = "JOINT-BILATERAL TO 640X360";
  EXPECT_EQ(hud_lines(s)[1], "MODE PATH  SPP 1  SCALE 0.50 (320X180)  TONE   UPSAMPLE JOINT-BILATERAL TO 640X360  AUTO 30 FPS");
  s.render_scale = 1.0f;
  EXPECT_EQ(hud_lines(s)[1].find("UPSAMPLE"), std::string::npos);
}

TEST(Hud, DrawsTheFramesTimelineAsABarPerTrack) {
  HudState s;
  core::FrameStats stats;
  stats.start_ms = 100.0;
  core::TracerFrameStats t;
  t.id = 0;
  t.name = "embree";
  stats.tracers.push_back(t);
  // The tracer renders for the whole frame; the core tone-maps in its last quarter.
  stats.stages.push_back({core::tracer_track(0, "embree"), "render", 100.0, 8.0});
  stats.stages.push_back({core::kCoreTrack, "tone map", 106.0, 2.0});
  s.stats = stats;
  raster::Image8 layer;
  layer.resize(400, 200);
  draw_hud(layer, s);
  auto count = [&](raster::Rgba8 c) {
    size_t n = 0;
    for (size_t i = 0; i < layer.rgba.size(); i += 4)
      n += layer.rgba[i] == c.r && layer.rgba[i + 1] == c.g && layer.rgba[i + 2] == c.b;
    return n;
  };
  const size_t render = count(stage_color("render")), tone = count(stage_color("tone map"));
  EXPECT_EQ(render, 160u * 5u) << "the render stage spans the whole 160-pixel axis, 5 pixels high";
  EXPECT_EQ(tone, 40u * 5u) << "tone map: a quarter of the axis";
}

// cohort play sizes the HUD layer by hud_extent instead of the window: nothing drawn may fall outside it,
// and it must not be much larger than what is drawn (the point is to blend fewer pixels).
TEST(Hud, ExtentHoldsEverythingDrawn) {
  for (const int scale : {1, 2}) {
    for (const bool with_timeline : {false, true}) {
      HudState s;
      s.mode = "PATH";
      s.notices.push_back("RIGHT MOUSE OR TAB: LOOK AROUND");
      if (with_timeline) {
        core::FrameStats stats;
        stats.start_ms = 0.0;
        for (int id : {0, 1}) {
          core::TracerFrameStats t;
          t.id = id;
          t.name = id == 0 ? "embree" : "opencl:0";
          stats.tracers.push_back(t);
          stats.stages.push_back({core::tracer_track(id, t.name), "render", 0.0, 8.0});
        }
        stats.stages.push_back({core::kCoreTrack, "tone map", 6.0, 2.0});
        s.stats = stats;
      }
      raster::Image8 layer;
      layer.resize(2000, 600);
      draw_hud(layer, s, scale);
      int right = -1, bottom = -1;
      for (int y = 0; y < layer.height; ++y)
        for (int x = 0; x < layer.width; ++x)
          if (layer.rgba[(static_cast<size_t>(y) * layer.width + x) * 4 + 3] != 0) {
            right = std::max(right, x);
            bottom = std::max(bottom, y);
          }
      const HudExtent extent = hud_extent(s, scale);
      ASSERT_GE(right, 0);
      EXPECT_EQ(extent.width, right + 1) << "scale " << scale << (with_timeline ? ", timeline" : "");
      EXPECT_EQ(extent.height, bottom + 1) << "scale " << scale << (with_timeline ? ", timeline" : "");
      EXPECT_LT(extent.width, 1280 / 2);
    }
  }
}

TEST(Hud, FormatsBytes) {
  EXPECT_EQ(format_bytes(512), "512 B");
  EXPECT_EQ(format_bytes(2048), "2.0 KB");
  EXPECT_EQ(format_bytes(3 * 1024 * 1024), "3.00 MB");
}

}  // namespace
}  // namespace cohort::viewer
