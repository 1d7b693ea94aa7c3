// Silhouettes under a G-buffer from each pixel's jittered sample (`--aux-rays first-hit`,
// ReprojectionOptions::jittered_planes): a pixel on the edge of a near surface sees the near surface one frame
// and the far one the next, so its id, depth and normal flip frame to frame. Its history must survive the flips
// (centre rays, whose surface does not flip, keep every sample of the pixel) and converge to the mix of the two
// surfaces, as the reference's many samples a pixel do; and a near surface that moves away must still leave
// none of its colour in what it uncovers.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "cohort/core/reprojection.h"

using namespace cohort::core;

namespace {

constexpr int kW = 32, kH = 16;
constexpr float kNearDepth = 5.0f, kFarDepth = 10.0f;
constexpr float kNear = 8.0f, kFar = 1.0f;
constexpr uint32_t kNearId = 3, kFarId = 0;

// One pixel's sample: which surface it met (near or far), and where that point was in the previous frame.
void set_sample(GBuffer& g, FrameBuffer& image, size_t p, bool near, float motion_x, float noise) {
  g.depth[p] = g.prev_depth[p] = near ? kNearDepth : kFarDepth;
  g.normal[3 * p + 2] = 1.0f;
  g.id[p] = near ? kNearId : kFarId;
  g.albedo[3 * p] = g.albedo[3 * p + 1] = g.albedo[3 * p + 2] = 0.5f;
  g.motion[2 * p] = motion_x;
  g.motion[2 * p + 1] = 0.0f;
  for (int k = 0; k < 3; ++k) image.rgba[4 * p + k] = (near ? kNear : kFar) * noise;
  image.rgba[4 * p + 3] = 1.0f;
}

// A still camera; the near surface covers columns x < edge, the far one x > edge; column `edge` is half
// covered, and its sample lands on either surface with even odds each frame (the jitter).
void make_still_frame(int edge, std::mt19937& rng, FrameBuffer& image, GBuffer& g) {
  image.resize(kW, kH);
  g.resize(kW, kH);
  std::uniform_real_distribution<float> noise(0.5f, 1.5f);
  std::bernoulli_distribution coin(0.5);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const bool near = x < edge || (x == edge && coin(rng));
      set_sample(g, image, static_cast<size_t>(y) * kW + x, near, 0.0f, noise(rng));
    }
}

struct Column {
  double colour = 0.0, length = 0.0;
  double off_mix = 0.0;  // mean |colour - mix| over its pixels
};

Column column_means(const TemporalReprojection& r, int x, double mix = 0.0) {
  Column c;
  for (int y = 0; y < kH; ++y) {
    const size_t p = static_cast<size_t>(y) * kW + x;
    const double v = r.image().rgba[4 * p + 1];
    c.colour += v / kH;
    c.off_mix += std::abs(v - mix) / kH;
    c.length += r.history_length()[p] / kH;
  }
  return c;
}

}  // namespace

TEST(ReprojectionSilhouettes, AJitteredEdgeKeepsItsHistoryAndConvergesToTheMixOfItsSurfaces) {
  constexpr int kEdge = 12, kFrames = 24;
  constexpr double kMix = 0.5 * (kNear + kFar);
  for (const bool moments : {false, true}) {
    SCOPED_TRACE(moments ? "with moments" : "without moments");
    auto run = [&](bool jittered_planes) {
      ReprojectionOptions o;
      o.jittered_planes = jittered_planes;
      o.luminance_moments = moments;
      TemporalReprojection r(o);
      std::mt19937 rng(11);
      FrameBuffer image;
      GBuffer g;
      for (int f = 0; f < kFrames; ++f) {
        make_still_frame(kEdge, rng, image, g);
        r.accumulate(image, g);
      }
      // Away from the edge nothing changes: every frame counts.
      EXPECT_FLOAT_EQ(column_means(r, kEdge - 3).length, kFrames);
      EXPECT_FLOAT_EQ(column_means(r, kEdge + 3).length, kFrames);
      return column_means(r, kEdge, kMix);
    };
    const Column kept = run(true);
    EXPECT_GT(kept.length, 0.9 * kFrames) << "the edge's history restarts when its sample changes surface";
    // Each pixel of the edge, not only their mean (half of them near, half far, would give that too).
    EXPECT_LT(kept.off_mix, 0.25 * kMix) << "the edge is not the mix of the surfaces it covers";
    // Without: a flip restarts the history (about 2 frames long at even odds), and each pixel shows one
    // surface's colour or the other's.
    const Column restarted = run(false);
    EXPECT_LT(restarted.length, 3.0);
    EXPECT_GT(restarted.off_mix, 0.5 * kMix);
  }
}

// The near surface slides right one pixel a frame past a still camera, its leading and trailing edges
// jittered as above. What it uncovers behind its trailing edge is the far wall: no share of the near
// surface's (8x brighter) history may stay there, although the near surface is right next to it (it moved:
// its motion vectors differ from the uncovered pixels' by a pixel).
TEST(ReprojectionSilhouettes, ASurfaceThatMovesAwayLeavesNoneOfItsColourBehind) {
  constexpr int kStart = 6, kWidth = 8, kFrames = 14;
  for (const bool jittered_planes : {false, true}) {
    SCOPED_TRACE(jittered_planes ? "jittered planes" : "centre planes");
    ReprojectionOptions o;
    o.jittered_planes = jittered_planes;
    TemporalReprojection r(o);
    std::mt19937 rng(13);
    std::uniform_real_distribution<float> noise(0.5f, 1.5f);
    std::bernoulli_distribution coin(0.5);
    FrameBuffer image;
    GBuffer g;
    image.resize(kW, kH);
    g.resize(kW, kH);
    for (int f = 0; f < kFrames; ++f) {
      const int left = kStart + f, right = left + kWidth;  // near in [left, right), edges half covered
      for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
          const bool near = (x > left && x < right - 1) || ((x == left || x == right - 1) && coin(rng));
          set_sample(g, image, static_cast<size_t>(y) * kW + x, near, near && f > 0 ? -1.0f : 0.0f, noise(rng));
        }
      r.accumulate(image, g);
      if (f < 2) continue;
      // The two columns it left last frame and the frame before: the far wall, with histories of 1-2 frames.
      for (int x : {left - 1, left - 2}) {
        const Column c = column_means(r, x);
        EXPECT_LT(c.colour, 1.5 * kFar) << "frame " << f << ", column " << x << ": the near surface's colour stayed";
      }
    }
  }
}
