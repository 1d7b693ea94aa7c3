// Every tracer reports the rays it traced per row of its band (BandResult::row_work), the per-row
// work the Row Cost and Whole Cost balancers cut by. The tracers trace the same rays for the same
// pixel samples, so their counts agree, row by row, up to paths that floating-point differences send
// another way.
#include <gtest/gtest.h>

#include <iostream>
#include <numeric>

#include "test_scenes.h"
#include "test_tracers.h"

using namespace cohort;
using namespace cohort::test;

namespace {

constexpr int kWidth = 64, kHeight = 48, kBegin = 10, kEnd = 40, kSpp = 2;

std::vector<float> row_work_of(const std::string& kind) {
  auto tracer = make_test_tracer(kind);
  const scene::Scene room = test_room();
  const KCamera cam = test_room_camera(kWidth, kHeight);
  auto compiled = std::make_shared<commit::TracerScene>(core::compile_scene(room).tracer_scene);
  tracer->apply(commit::CommitBuffer::full(compiled, 1));
  core::FrameBuffer fb;
  fb.resize(kWidth, kHeight);
  core::BandJob job;
  job.params = frame_params(K_MODE_PATH, kSpp, 1, kHeight);
  job.params.row_begin = kBegin;
  job.params.row_end = kEnd;
  job.camera = cam;
  return tracer->render_band(job, fb).row_work;
}

}  // namespace

TEST(RowWork, EveryTracerCountsTheRaysOfEachRowOfItsBand) {
  std::vector<std::vector<float>> counts;
  std::vector<std::string> kinds;
  for (const std::string& kind : built_tracers()) {
    if (!tracer_runs_here(kind)) continue;
    const std::vector<float> work = row_work_of(kind);
    ASSERT_EQ(work.size(), static_cast<size_t>(kEnd - kBegin)) << kind;
    for (size_t r = 0; r < work.size(); ++r) {
      // Each sample traces a camera ray, and the lit room gives most of them a shadow ray or a bounce.
      EXPECT_GE(work[r], kWidth * kSpp) << kind << " row " << kBegin + r;
      EXPECT_LE(work[r], kWidth * kSpp * 16) << kind << " row " << kBegin + r;
    }
    counts.push_back(work);
    kinds.push_back(kind);
  }
  if (counts.empty()) GTEST_SKIP() << "no tracer runs here";
  for (size_t t = 0; t < counts.size(); ++t)
    std::cout << kinds[t] << ": " << std::accumulate(counts[t].begin(), counts[t].end(), 0.0) << " rays in " << counts[t].size() << " rows\n";
  for (size_t t = 1; t < counts.size(); ++t) {
    for (size_t r = 0; r < counts[0].size(); ++r)
      EXPECT_NEAR(counts[t][r], counts[0][r], 0.03 * counts[0][r]) << kinds[t] << " vs " << kinds[0] << ", row " << kBegin + r;
  }
}
