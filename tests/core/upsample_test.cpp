// Dynamic resolution's reconstruction (core/upsample.h, kernel/upsample.h) on synthetic planes: the
// traced pixels of a sparse pattern fill the frame, edges in the guide stay sharp, flat regions keep the
// traced value and textures come back from the full-resolution albedo.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>

#include <glm/glm.hpp>

#include "cohort/core/upsample.h"
#include "cohort/kernel/path_pattern.h"

using namespace cohort;
using namespace cohort::core;

namespace {

constexpr int kW = 40, kH = 24;

struct Planes {
  FrameBuffer sparse;
  GBuffer g;
};

// A frame whose traced pixels hold colour(x, y) (others NaN, which the reconstruction must never read),
// with depth, normal, albedo and id from the given functions.
Planes make_planes(PathPattern pattern, const std::function<float(int, int)>& depth,
                   const std::function<glm::vec3(int, int)>& normal, const std::function<glm::vec3(int, int)>& albedo,
                   const std::function<glm::vec3(int, int)>& colour, const std::function<uint32_t(int, int)>& id) {
  Planes p;
  p.sparse.resize(kW, kH);
  p.g.resize(kW, kH);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const size_t i = static_cast<size_t>(y) * kW + x;
      const bool traced = k_pixel_traces_path(pattern.pixels, pattern.phase, kuint(x), kuint(y));
      const glm::vec3 c = traced ? colour(x, y) : glm::vec3(std::numeric_limits<float>::quiet_NaN());
      const glm::vec3 n = normal(x, y), a = albedo(x, y);
      for (int k = 0; k < 3; ++k) {
        p.sparse.rgba[4 * i + k] = c[k];
        p.g.normal[3 * i + k] = n[k];
        p.g.albedo[3 * i + k] = a[k];
      }
      p.sparse.rgba[4 * i + 3] = 1.0f;
      p.g.depth[i] = depth(x, y);
      p.g.id[i] = id(x, y);
    }
  return p;
}

glm::vec3 up(int, int) { return {0.0f, 0.0f, 1.0f}; }
glm::vec3 grey(int, int) { return glm::vec3(0.5f); }
uint32_t world(int, int) { return 0u; }
float flat(int, int) { return 100.0f; }

glm::vec3 at(const FrameBuffer& f, int x, int y) {
  const float* p = f.row(y) + 4 * x;
  return {p[0], p[1], p[2]};
}

const PathPattern kQuarter{4, 0};  // scale 0.5: a lattice of stride 2

}  // namespace

TEST(PathPattern, ScaleHalfTracesOnePixelOfEach2x2AndFourFramesCoverEveryPixelOnce) {
  std::vector<int> times(kW * kH, 0);
  for (uint64_t frame = 0; frame < 4; ++frame) {
    const PathPattern p = path_pattern_for_scale(0.5, frame);
    ASSERT_EQ(p.pixels, 4u);
    for (int by = 0; by < kH; by += 2)
      for (int bx = 0; bx < kW; bx += 2) {
        int in_block = 0;
        for (int y = by; y < by + 2; ++y)
          for (int x = bx; x < bx + 2; ++x)
            if (k_pixel_traces_path(p.pixels, p.phase, kuint(x), kuint(y))) {
              ++in_block;
              ++times[y * kW + x];
            }
        ASSERT_EQ(in_block, 1) << "frame " << frame << " block " << bx << "," << by;
      }
  }
  for (int t : times) ASSERT_EQ(t, 1);
}

TEST(PathPattern, EveryCountTracesThatManyPixelsOfEachBlockAtEveryPhase) {
  for (kuint pixels = 1; pixels < 16; ++pixels)
    for (kuint phase = 0; phase < 16; ++phase) {
      int traced = 0;
      for (kuint y = 4; y < 8; ++y)
        for (kuint x = 8; x < 12; ++x) traced += k_pixel_traces_path(pixels, phase, x, y);
      ASSERT_EQ(traced, int(pixels)) << pixels << " pixels, phase " << phase;
    }
  EXPECT_FALSE(path_pattern_for_scale(1.0, 3).sparse());
  EXPECT_EQ(path_pattern_for_scale(0.1, 0).pixels, 1u);  // never none
  EXPECT_EQ(path_pattern_for_scale(0.7, 0).pixels, 8u);  // a checkerboard
}

TEST(Upsample, FlatRegionKeepsTheTracedValueEverywhere) {
  for (UpsampleMethod m : {UpsampleMethod::joint_bilateral, UpsampleMethod::nearest})
    for (PathPattern pattern : {kQuarter, PathPattern{4, 8}, PathPattern{1, 5}, PathPattern{8, 0}, PathPattern{11, 3}}) {
      const Planes p = make_planes(pattern, flat, up, grey, [](int, int) { return glm::vec3(0.3f, 0.6f, 0.9f); }, world);
      FrameBuffer out;
      upsample_sparse(p.sparse, p.g, pattern, m, out);
      for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
          const glm::vec3 c = at(out, x, y);
          ASSERT_NEAR(c.r, 0.3f, 1e-5f) << upsample_method_name(m) << " " << pattern.pixels << " at " << x << "," << y;
          ASSERT_NEAR(c.g, 0.6f, 1e-5f);
          ASSERT_NEAR(c.b, 0.9f, 1e-5f);
        }
    }
}

// A wall in front of a far floor, both facing the camera: depth 100 left of column 17, 400 right of it;
// colour 1 on the near side, 8 on the far one. Pixels on either side must not take the other's light.
TEST(Upsample, DepthEdgeStaysSharp) {
  auto depth = [](int x, int) { return x < 17 ? 100.0f : 400.0f; };
  auto colour = [](int x, int) { return glm::vec3(x < 17 ? 1.0f : 8.0f); };
  const Planes p = make_planes(kQuarter, depth, up, grey, colour, world);
  FrameBuffer out;
  upsample_sparse(p.sparse, p.g, kQuarter, UpsampleMethod::joint_bilateral, out);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) ASSERT_NEAR(at(out, x, y).r, x < 17 ? 1.0f : 8.0f, 1e-3f) << x << "," << y;
  // The bilinear stretch of the same light at half size mixes the two sides at the edge.
  FrameBuffer low, stretched;
  low.resize(kW / 2, kH / 2);
  for (int y = 0; y < kH / 2; ++y)
    for (int x = 0; x < kW / 2; ++x)
      for (int k = 0; k < 3; ++k) low.row(y)[4 * x + k] = 2 * x < 17 ? 1.0f : 8.0f;
  stretch_bilinear(low, kW, kH, stretched);
  EXPECT_GT(at(stretched, 17, 5).r - 1.0f, 0.5f);
  EXPECT_GT(8.0f - at(stretched, 16, 5).r, 0.5f);
}

// A crease: same depth, the normal turns 90 degrees at row 11; and an object (another id) at equal depth.
TEST(Upsample, NormalAndObjectEdgesStaySharp) {
  auto normal = [](int, int y) { return y < 11 ? glm::vec3(0, 0, 1) : glm::vec3(1, 0, 0); };
  auto id = [](int x, int) { return x < 25 ? 0u : 7u; };
  auto colour = [](int x, int y) { return glm::vec3(x < 25 ? (y < 11 ? 1.0f : 3.0f) : 20.0f); };
  const Planes p = make_planes(kQuarter, flat, normal, grey, colour, id);
  FrameBuffer out;
  upsample_sparse(p.sparse, p.g, kQuarter, UpsampleMethod::joint_bilateral, out);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) ASSERT_NEAR(at(out, x, y).r, colour(x, y).r, 1e-3f) << x << "," << y;
}

// Constant light on a checkered texture: untraced pixels get the light times their own albedo, so the
// texture is as sharp as the G-buffer; the nearest traced pixel brings its neighbour's texel instead.
TEST(Upsample, TexturesComeBackFromTheFullResolutionAlbedo) {
  auto albedo = [](int x, int y) { return glm::vec3((x + y) % 2 ? 0.8f : 0.1f, 0.5f, (x / 3) % 2 ? 0.2f : 0.6f); };
  auto colour = [&](int x, int y) { return 2.0f * albedo(x, y); };
  const Planes p = make_planes(kQuarter, flat, up, albedo, colour, world);
  FrameBuffer joint, nearest;
  upsample_sparse(p.sparse, p.g, kQuarter, UpsampleMethod::joint_bilateral, joint);
  upsample_sparse(p.sparse, p.g, kQuarter, UpsampleMethod::nearest, nearest);
  double nearest_error = 0.0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      for (int k = 0; k < 3; ++k) ASSERT_NEAR(at(joint, x, y)[k], colour(x, y)[k], 1e-4f) << x << "," << y;
      nearest_error += std::fabs(at(nearest, x, y).r - colour(x, y).r);
    }
  EXPECT_GT(nearest_error / (kW * kH), 0.3);
}

// Camera misses (depth 0) only take misses; a surface pixel whose kind no traced tap shares still gets
// light (the spatial fallback) rather than black.
TEST(Upsample, MissesStayApartAndALoneSurfacePixelIsNotBlack) {
  auto depth = [](int x, int y) { return (x == 21 && y == 9) ? 50.0f : x < 10 ? 0.0f : 100.0f; };
  auto colour = [](int x, int) { return glm::vec3(x < 10 ? 0.25f : 4.0f); };
  const Planes p = make_planes(kQuarter, depth, up, grey, colour, world);
  ASSERT_FALSE(k_pixel_traces_path(kQuarter.pixels, kQuarter.phase, 21, 9));
  FrameBuffer out;
  upsample_sparse(p.sparse, p.g, kQuarter, UpsampleMethod::joint_bilateral, out);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < 15; ++x) ASSERT_NEAR(at(out, x, y).r, x < 10 ? 0.25f : 4.0f, 1e-3f) << x << "," << y;
  EXPECT_NEAR(at(out, 21, 9).r, 4.0f, 1e-3f);  // depth 50 among 100s: no guided tap, the spatial fallback
}

TEST(Upsample, NonFiniteTracedPixelsAreLeftOut) {
  auto colour = [](int x, int y) {
    return x == 10 && y == 10 ? glm::vec3(std::numeric_limits<float>::infinity()) : glm::vec3(1.5f);
  };
  const Planes p = make_planes(kQuarter, flat, up, grey, colour, world);
  FrameBuffer out;
  upsample_sparse(p.sparse, p.g, kQuarter, UpsampleMethod::joint_bilateral, out);
  for (float v : out.rgba) ASSERT_TRUE(std::isfinite(v));
  EXPECT_NEAR(at(out, 11, 10).r, 1.5f, 1e-5f);
}

TEST(Upsample, AGBufferOfAnotherSizeIsAnError) {
  FrameBuffer sparse, out;
  sparse.resize(8, 8);
  GBuffer g;
  g.resize(4, 4);
  EXPECT_THROW(upsample_sparse(sparse, g, kQuarter, UpsampleMethod::joint_bilateral, out), std::invalid_argument);
  EXPECT_THROW(parse_upsample_method("bicubic"), std::invalid_argument);
}
