// Sparse paths for dynamic resolution (kernel/path_pattern.h): with KFrameParams.path_pixels set, every
// tracer traces paths only at the pattern's pixels, with the same samples a full frame draws there, and
// leaves the others black; the aux planes still cover every pixel (core/upsample.h reconstructs from them).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "cohort/kernel/path_pattern.h"
#include "test_scenes.h"
#include "test_tracers.h"

using namespace cohort;
using namespace cohort::test;

namespace {

constexpr int kW = 64, kH = 48;

KFrameParams sparse_params(kuint pixels, kuint phase) {
  KFrameParams p = frame_params(K_MODE_PATH, 4, 1, kH);
  p.frame_index = 5;
  p.path_pixels = pixels;
  p.path_phase = phase;
  return p;
}

// Traced pixels must equal `full` within `tolerance` of its mean (0: to float rounding), the others be black.
void expect_sparse_copy(const core::FrameBuffer& sparse, const core::FrameBuffer& full, kuint pixels, kuint phase,
                        double tolerance, const std::string& what) {
  double sum = 0.0, error = 0.0, mean = 0.0;
  int traced = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const float* s = sparse.row(y) + 4 * x;
      const float* f = full.row(y) + 4 * x;
      if (!k_pixel_traces_path(pixels, phase, kuint(x), kuint(y))) {
        ASSERT_EQ(s[0] + s[1] + s[2], 0.0f) << what << ": untraced pixel " << x << "," << y;
        continue;
      }
      ++traced;
      for (int k = 0; k < 3; ++k) {
        ASSERT_TRUE(std::isfinite(s[k])) << what;
        error += (double(s[k]) - f[k]) * (double(s[k]) - f[k]);
        sum += f[k];
        if (tolerance == 0.0) {
          ASSERT_NEAR(s[k], f[k], 1e-5f * (1.0f + std::fabs(f[k]))) << what << " " << x << "," << y;
        }
      }
    }
  EXPECT_EQ(traced, kW * kH * int(pixels) / 16) << what;
  mean = sum / (3.0 * traced);
  EXPECT_GT(mean, 0.01) << what << ": the room should be lit";
  if (tolerance > 0.0) {
    EXPECT_LT(std::sqrt(error / (3.0 * traced)), tolerance * mean) << what;
  }
}

}  // namespace

TEST(SparsePaths, EmbreeTracesExactlyThePatternsPixelsAsAFullFrameWould) {
  if (!tracer_runs_here("embree")) GTEST_SKIP();
  auto embree = make_test_tracer("embree");
  const KCamera cam = test_room_camera(kW, kH);
  const core::FrameBuffer full = render(*embree, test_room(), cam, sparse_params(0, 0));
  for (kuint pixels : {1u, 4u, 7u})
    for (kuint phase : {0u, 4u, 13u}) {
      const core::FrameBuffer sparse = render(*embree, test_room(), cam, sparse_params(pixels, phase));
      expect_sparse_copy(sparse, full, pixels, phase, 0.0,
                         "embree " + std::to_string(pixels) + " of 16, phase " + std::to_string(phase));
    }
}

// The GPU kernels ask the same predicate (k_render_pixel): their traced pixels agree with Embree's full
// frame as the tracers agree on full frames (agreement_test.cpp), and their untraced pixels are black.
class SparsePathsOnDevices : public ::testing::TestWithParam<std::string> {};

TEST_P(SparsePathsOnDevices, TraceThePatternsPixelsLikeEmbree) {
  const std::string device = GetParam();
  if (!tracer_runs_here("embree") || !tracer_runs_here(device)) GTEST_SKIP() << "needs Embree and " << device;
  auto embree = make_test_tracer("embree");
  auto other = make_test_tracer(device);
  const KCamera cam = test_room_camera(kW, kH);
  const core::FrameBuffer full = render(*embree, test_room(), cam, sparse_params(0, 0));
  const core::FrameBuffer sparse = render(*other, test_room(), cam, sparse_params(4, 8));
  expect_sparse_copy(sparse, full, 4, 8, 0.02, device + " 4 of 16");
}

INSTANTIATE_TEST_SUITE_P(Devices, SparsePathsOnDevices, ::testing::Values("opencl", "cuda"),
                         [](const auto& info) { return info.param; });

// Sparse frames still write every pixel's aux planes (the reconstruction's guide), the same as a full frame's.
TEST(SparsePaths, AuxPlanesCoverEveryPixel) {
  if (!tracer_runs_here("embree")) GTEST_SKIP();
  auto embree = make_test_tracer("embree");
  const KCamera cam = test_room_camera(kW, kH);
  auto room = std::make_shared<commit::TracerScene>(core::compile_scene(test_room()).tracer_scene);
  embree->apply(commit::CommitBuffer::full(room, 1));
  auto aux = [&](kuint pixels) {
    core::BandBuffer band(kW, kH, core::BandFormat::rgba32f);
    band.enable_aux(true);
    core::BandJob job;
    job.params = sparse_params(pixels, 0);
    job.params.aux_outputs = 1u;
    job.camera = cam;
    job.previous_camera = cam;
    embree->render_band(job, band);
    core::GBuffer g;
    g.resize(kW, kH);
    band.copy_aux_rows_to(g, 0, kH);
    return g;
  };
  const core::GBuffer full = aux(0), sparse = aux(4);
  int surfaces = 0;
  for (size_t p = 0; p < full.pixels(); ++p) {
    surfaces += full.depth[p] > 0.0f;
    ASSERT_EQ(sparse.depth[p], full.depth[p]) << p;
    ASSERT_EQ(sparse.id[p], full.id[p]) << p;
    for (int k = 0; k < 3; ++k) ASSERT_EQ(sparse.albedo[3 * p + k], full.albedo[3 * p + k]) << p;
  }
  EXPECT_GT(surfaces, kW * kH / 2);
}
