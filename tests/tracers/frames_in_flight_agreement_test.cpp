// Two frames in flight on real tracers (Embree, and OpenCL where it runs: PoCL here): over the test map
// with its animated materials (commits every frame) and a turning camera, the frames the pipeline delivers
// are the frames it delivers with one in flight, bit for bit where the band split is the same (the even
// split of `none`) or where one integrator draws both sides of the border (two Embree tracers), else within
// the agreement bound.
#include <gtest/gtest.h>

#include <string>

#include "cohort/core/frame_pipeline.h"
#include "cohort/core/renderer.h"
#include "cohort/core/view.h"
#include "cohort/core/world_sync.h"
#include "cohort/scene/map_loader.h"
#include "cohort/scene/render_world.h"
#include "test_scenes.h"
#include "test_tracers.h"

using namespace cohort;
using namespace cohort::test;

namespace {

constexpr int kWidth = 64, kHeight = 40, kFrames = 8;

struct Rendered {
  std::vector<core::FrameBuffer> images;
  std::vector<core::FrameStats> stats;
};

// kFrames of the test map's hall, each frame a little later (its materials change: commits every frame)
// and the camera a little further round, through the pipeline as `cohort render` drives it.
Rendered render_sequence(const std::vector<std::string>& tracer_names, const std::string& balancer, int in_flight) {
  scene::Scene map = load_test_map();
  scene::RenderWorld world(map);
  core::WorldSyncOptions sync_options;
  sync_options.width = kWidth, sync_options.height = kHeight;
  core::WorldSync sync(world, sync_options);
  world.TakeChanges();
  std::vector<std::unique_ptr<core::Tracer>> tracers;
  for (const std::string& name : tracer_names) tracers.push_back(make_test_tracer(name));
  core::RendererOptions options;
  options.balancer = balancer;
  options.frames_in_flight = in_flight;
  options.frame_timeout = std::chrono::milliseconds(120000);
  core::Renderer renderer(std::move(tracers), options);
  renderer.submit_commit(commit::CommitBuffer::full(sync.snapshot(), 0));
  core::FramePipeline pipeline(renderer);
  Rendered out;
  auto take = [&](std::optional<core::FramePipeline::Delivered> done) {
    if (!done) return;
    out.images.push_back(pipeline.image());
    out.stats.push_back(std::move(done->stats));
  };
  for (int f = 0; f < kFrames; ++f) {
    if (f > 0) {
      sync.set_time(0.3 * f);
      const commit::CommitBuffer records = sync.sync(world.TakeChanges(), uint64_t(f));
      EXPECT_FALSE(records.empty()) << "frame " << f << ": the materials change every frame";
      renderer.submit_commit(records, [&] { return sync.snapshot(); });
    }
    core::BandJob job;
    job.camera = core::make_camera({300, 192, 80}, {180.0f + 4.0f * float(f), 0.0f}, 90.0f, kWidth, kHeight);
    job.params = testmap_agreement_params(kHeight);
    job.params.spp = 2;
    job.params.frame_index = static_cast<kuint>(f);
    take(pipeline.push(job));
  }
  take(pipeline.drain());
  return out;
}

void expect_same_frames(const Rendered& one, const Rendered& two, bool bit_for_bit, const std::string& label) {
  ASSERT_EQ(one.images.size(), size_t(kFrames)) << label;
  ASSERT_EQ(two.images.size(), size_t(kFrames)) << label;
  for (int f = 0; f < kFrames; ++f) {
    EXPECT_EQ(two.stats[f].frame, uint64_t(f)) << label;
    const core::FrameBuffer& a = one.images[f];
    const core::FrameBuffer& b = two.images[f];
    double mean = 0.0;
    const double error = rgb_rmse(a, b, &mean);
    EXPECT_GT(mean, 0.01) << label << " frame " << f;
    if (bit_for_bit) {
      EXPECT_EQ(error, 0.0) << label << " frame " << f << ": one pixel or more differ";
    } else {
      EXPECT_LT(error, 0.005 * mean) << label << " frame " << f;
    }
    if (f > 0) {
      double unused = 0.0;
      EXPECT_GT(rgb_rmse(a, one.images[f - 1], &unused), 0.0) << label << ": the sequence should move";
    }
  }
}

}  // namespace

TEST(FramesInFlightAgreement, TwoEmbreeTracersDrawTheSameFramesWithTwoInFlightWhereverTheBorderGoes) {
  if (!tracer_runs_here("embree")) GTEST_SKIP() << "needs the Embree tracer";
  // Every pixel from the same integrator: which Embree tracer drew it does not matter, so the border that
  // Robin Hood moves every frame, divided one frame later with two in flight, changes nothing.
  const Rendered one = render_sequence({"embree", "embree"}, "robin-hood", 1);
  const Rendered two = render_sequence({"embree", "embree"}, "robin-hood", 2);
  expect_same_frames(one, two, true, "embree,embree");
  int moved = 0;
  for (int f = 0; f < kFrames; ++f) moved += one.stats[f].tracers[0].row_end != two.stats[f].tracers[0].row_end;
  EXPECT_GT(moved, 0) << "the border should sit elsewhere in some frame with two in flight, or nothing was tested";
}

TEST(FramesInFlightAgreement, EmbreeAndOpenCLDrawTheSameFramesWithTwoInFlight) {
  if (!tracer_runs_here("embree") || !tracer_runs_here("opencl")) GTEST_SKIP() << "needs the Embree and OpenCL tracers";
  // The even split: the same rows on the same tracer either way, so the same bits.
  expect_same_frames(render_sequence({"embree", "opencl"}, "none", 1), render_sequence({"embree", "opencl"}, "none", 2),
                     true, "embree,opencl even split");
  // Rows divided by measured costs move between the two tracers differently: the agreement bound.
  expect_same_frames(render_sequence({"embree", "opencl"}, "perfect-smooth", 1),
                     render_sequence({"embree", "opencl"}, "perfect-smooth", 2), false, "embree,opencl balanced");
}
