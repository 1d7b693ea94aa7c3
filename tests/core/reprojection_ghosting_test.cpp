// Ghosting (issue 17: "FLIP on the moving door's pixels <= 0.1 after 4 still frames"), on the host's
// reprojection, which runs the portable kernel (kernel/reproject.h) that CudaFramePost runs too.
// A door in a wall slides up out of its doorway while the camera pans, then stops: the far room it
// uncovers must show what is behind it, not the door, and the door must keep its own colour, not the
// wall's. Behind the door: a far room (the depth test alone tells it from the door), or a panel just
// behind it, within the depth tolerance (only the id tells them apart).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "cohort/core/reprojection.h"

using namespace cohort::core;

namespace {

constexpr int kW = 48, kH = 24;
constexpr int kDoorX0 = 16, kDoorX1 = 30, kDoorY0 = 4, kDoorY1 = 18;  // the doorway, in world pixels
constexpr int kDoorRisePerFrame = 2, kMovingFrames = 4;
constexpr float kWallDepth = 10.0f, kDoorDepth = 10.2f;  // the door sits in the wall's depth band
constexpr float kWall = 1.0f, kDoor = 20.0f, kFar = 0.2f;
constexpr uint32_t kDoorId = 3, kWorldId = 0;

enum class Surface { wall, door, far_room };

// What frame `frame`'s camera sees at pixel (x, y): the camera pans right one pixel a frame, the door's
// bottom edge rises kDoorRisePerFrame rows a frame for kMovingFrames frames (its top slides behind the wall).
Surface surface_at(int frame, int x, int y) {
  const int wx = x + frame;
  if (wx < kDoorX0 || wx >= kDoorX1 || y < kDoorY0 || y >= kDoorY1) return Surface::wall;
  const int door_bottom = kDoorY1 - kDoorRisePerFrame * std::min(frame, kMovingFrames);
  return y < door_bottom ? Surface::door : Surface::far_room;
}

// The frame's G-buffer (what the tracers write, kernel/aux_outputs.h) and a noisy 1-spp-like image of it.
void make_frame(int frame, float behind_depth, std::mt19937& rng, FrameBuffer& image, GBuffer& g) {
  image.resize(kW, kH);
  g.resize(kW, kH);
  std::uniform_real_distribution<float> noise(0.5f, 1.5f);
  const bool door_moving = frame > 0 && frame <= kMovingFrames;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const size_t p = static_cast<size_t>(y) * kW + x;
      const Surface s = surface_at(frame, x, y);
      const float depth = s == Surface::wall ? kWallDepth : s == Surface::door ? kDoorDepth : behind_depth;
      g.depth[p] = g.prev_depth[p] = depth;
      g.normal[3 * p] = 1.0f;  // all facing the camera (+x toward it in this test's world)
      g.id[p] = s == Surface::door ? kDoorId : kWorldId;
      g.albedo[3 * p] = g.albedo[3 * p + 1] = g.albedo[3 * p + 2] = 0.5f;
      // Content moves left with the pan: what pixel x shows was at x + 1; the door's points were lower.
      g.motion[2 * p] = frame > 0 ? 1.0f : 0.0f;
      g.motion[2 * p + 1] = s == Surface::door && door_moving ? static_cast<float>(kDoorRisePerFrame) : 0.0f;
      const float colour = s == Surface::wall ? kWall : s == Surface::door ? kDoor : kFar;
      const float n = noise(rng);
      for (int k = 0; k < 3; ++k) image.rgba[4 * p + k] = colour * n;
      image.rgba[4 * p + 3] = 1.0f;
    }
}

struct RegionMean {
  double sum = 0.0;
  int count = 0;
  double mean() const { return count > 0 ? sum / count : 0.0; }
};

}  // namespace

TEST(ReprojectionGhosting, TheDoorLeavesNoTrailAndKeepsItsColourAfterFourStillFrames) {
  for (const float behind_depth : {30.0f, 10.5f})
  for (const bool moments : {false, true})
  for (const bool anti_lag : {false, true})
  for (const bool jittered_planes : {false, true}) {  // the footprint taps must not let the door into the doorway
    ReprojectionOptions o;
    o.luminance_moments = moments;
    o.jittered_planes = jittered_planes;
    if (!anti_lag) o.anti_lag_sigma = 0.0f;
    TemporalReprojection r(o);
    std::mt19937 rng(5);
    FrameBuffer image;
    GBuffer g;
    // Frames 0..kMovingFrames: the door rises; then 4 still frames (the camera keeps panning).
    const int last_frame = kMovingFrames + 4;
    for (int frame = 0; frame <= last_frame; ++frame) {
      make_frame(frame, behind_depth, rng, image, g);
      r.accumulate(image, g);
      RegionMean uncovered, door, wall;
      for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
          const size_t p = static_cast<size_t>(y) * kW + x;
          const float v = r.image().rgba[4 * p + 1];
          const Surface s = surface_at(frame, x, y);
          // The far room the door uncovered, away from the doorway's side edges (bilinear taps there are
          // the wall's, correctly rejected or not, which this test does not judge).
          const int wx = x + frame;
          if (s == Surface::far_room && wx > kDoorX0 && wx < kDoorX1 - 1) uncovered.sum += v, ++uncovered.count;
          if (s == Surface::door && wx > kDoorX0 && wx < kDoorX1 - 1 && y > kDoorY0) door.sum += v, ++door.count;
          if (s == Surface::wall && (wx < kDoorX0 - 1 || wx > kDoorX1) && x < kW - 1) wall.sum += v, ++wall.count;
        }
      SCOPED_TRACE(testing::Message() << "frame " << frame << ", behind the door at depth " << behind_depth
                                      << (moments ? ", with moments" : "") << (anti_lag ? ", anti-lag" : "")
                                      << (jittered_planes ? ", jittered planes" : ""));
      if (frame > 0) {
        ASSERT_GT(uncovered.count, 0);
        // A ghost: any share of the door's history (100x brighter) in the far room shows at once.
        EXPECT_NEAR(uncovered.mean(), kFar, 0.25 * kFar) << "what the door uncovered keeps its colour";
      }
      ASSERT_GT(door.count, 0);
      EXPECT_NEAR(door.mean(), kDoor, 0.1 * kDoor) << "the door takes another surface's colour";
      EXPECT_NEAR(wall.mean(), kWall, 0.1 * kWall);
    }
    // After 4 still frames the door's history has grown with it: it kept its samples while it moved (the
    // anti-lag, which cannot tell this noise from a lighting change of its size, trims some of it).
    const size_t door_pixel = static_cast<size_t>(kDoorY0 + 2) * kW + (kDoorX0 + 4 - last_frame);
    EXPECT_GE(r.history_length()[door_pixel], anti_lag ? 2.0f : static_cast<float>(last_frame))
        << "the door lost its history";
  }
}

// Ghosting of lighting: the light on a wall rises fivefold (a door letting light in, a flashlight's pool
// arriving, a flicker) while the camera pans. At 1 spp the fresh samples are sparse (0 or 4x the mean),
// so the 3x3 clamp box reaches down to 0 and keeps the old, darker history: a long history would fade in
// the new light over tens of frames. The anti-lag (kernel/reproject.h, k_reproject_anti_lag) sees the
// 5x5 means part and lets it in.
TEST(ReprojectionGhosting, ALightThatBrightensIsNotHeldBackByTheHistory) {
  constexpr int kBefore = 20, kAfter = 4;
  constexpr float kDim = 2.0f, kBright = 10.0f;
  auto run = [&](bool anti_lag) {
    ReprojectionOptions o;
    if (!anti_lag) o.anti_lag_sigma = 0.0f;
    TemporalReprojection r(o);
    std::mt19937 rng(9);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    GBuffer g;
    g.resize(kW, kH);
    FrameBuffer image;
    image.resize(kW, kH);
    for (size_t p = 0; p < g.pixels(); ++p) {
      g.depth[p] = g.prev_depth[p] = kWallDepth;
      g.normal[3 * p] = 1.0f;
      g.id[p] = kWorldId;
    }
    RegionMean wall;
    for (int frame = 0; frame < kBefore + kAfter; ++frame) {
      const float level = frame < kBefore ? kDim : kBright;
      for (size_t p = 0; p < g.pixels(); ++p) {
        g.motion[2 * p] = frame > 0 ? 1.0f : 0.0f;  // panning: every pixel moves
        const float sample = u(rng) < 0.25f ? 4.0f * level : 0.0f;
        for (int k = 0; k < 3; ++k) image.rgba[4 * p + k] = sample;
        image.rgba[4 * p + 3] = 1.0f;
      }
      r.accumulate(image, g);
    }
    for (int y = 2; y < kH - 2; ++y)
      for (int x = 2; x < kW - 3; ++x) wall.sum += r.image().rgba[4 * (static_cast<size_t>(y) * kW + x) + 1], ++wall.count;
    return wall.mean();
  };
  const double with_anti_lag = run(true), without = run(false);
  EXPECT_GT(with_anti_lag, 0.75 * kBright) << kAfter << " frames after the light rose";  // 8.5 measured
  EXPECT_LT(with_anti_lag, 1.2 * kBright);
  // The case the anti-lag is for: without it the old light stays (the clamp alone cannot catch it).
  EXPECT_LT(without, 0.5 * kBright);  // 3.1 measured
}
