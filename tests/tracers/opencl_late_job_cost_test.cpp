// The OpenCL tracer's cost for the balancer (OpenCLTracer::Options::late_job_cost): with two frames in flight,
// a band that could not be enqueued ahead (no next job came while the band before rendered) costs its wall
// time less its enqueueing, a band that went ahead its wall time (BandResult::balance_ms 0), and with one frame
// in flight (no band ever ahead) every band costs its wall time. The Renderer's queued_next hook is played here
// by the test: the job after the first band is queued while the first renders, none after that.
#include <gtest/gtest.h>

#include <chrono>
#include <optional>
#include <vector>

#include "band_frames.h"
#include "test_scenes.h"
#include "test_tracers.h"

#ifdef COHORT_HAVE_OPENCL
#include "cohort/tracers/opencl_tracer.h"
#endif

using namespace cohort;
using namespace cohort::test;

#ifdef COHORT_HAVE_OPENCL
namespace {

struct Band {
  core::BandResult result;
  double wall_ms = 0.0;
};

// Three bands of consecutive frames into one target; with `two_in_flight` the second band's job is handed
// to the tracer while the first renders (so it goes ahead), the third's only when it starts.
std::vector<Band> render_three(bool late_job_cost, bool two_in_flight, size_t* enqueued_ahead) {
  tracers::OpenCLTracer::Options o;
  o.device = test_opencl_device();
  o.transfer_queue = tracers::OpenCLTracer::Options::TransferQueue::always;
  o.late_job_cost = late_job_cost;
  tracers::OpenCLTracer tracer(o);
  const int w = 48, h = 24;
  const View view = room_view(w, h);
  tracer.apply(commit::CommitBuffer::full(view.scene, 1));
  core::BandBuffer target;
  target.resize(w, h, core::BandFormat::rgba32f);
  std::vector<core::BandJob> jobs(3);
  for (kuint f = 0; f < 3; ++f) {
    jobs[f].params = frame_params(K_MODE_PATH, 1, 1, h);
    jobs[f].params.frame_index = f;
    jobs[f].camera = view.camera;
  }
  int handed = 0;
  if (two_in_flight)
    tracer.set_queued_next(
        [&](const core::Tracer::BandDone&) -> std::optional<core::Tracer::QueuedNext> {
          if (handed++ > 0) return std::nullopt;
          return core::Tracer::QueuedNext{jobs[1], &target};
        },
        [] {});
  std::vector<Band> bands;
  for (const core::BandJob& job : jobs) {
    const auto start = std::chrono::steady_clock::now();
    Band b;
    b.result = tracer.render_band(job, target);
    b.wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    bands.push_back(b);
  }
  *enqueued_ahead = tracer.bands_enqueued_ahead();
  return bands;
}

}  // namespace

TEST(OpenCLLateJobCost, ABandThatCouldNotGoAheadCostsItsWallTimeLessItsEnqueueing) {
  if (!tracer_runs_here("opencl")) GTEST_SKIP() << "needs the OpenCL tracer";
  size_t ahead = 0;
  const std::vector<Band> bands = render_three(true, true, &ahead);
  ASSERT_EQ(ahead, 1u) << "the second band should have gone ahead";
  // The first band is not ahead and the second went ahead inside it: it already counts as late.
  EXPECT_GT(bands[0].result.balance_ms, 0.0);
  EXPECT_EQ(bands[1].result.balance_ms, 0.0) << "a band that went ahead costs its wall time";
  EXPECT_GT(bands[2].result.balance_ms, 0.0) << "a band whose job came late costs less than its wall time";
  EXPECT_LT(bands[2].result.balance_ms, bands[2].wall_ms);
}

TEST(OpenCLLateJobCost, OffOrWithOneFrameInFlightEveryBandCostsItsWallTime) {
  if (!tracer_runs_here("opencl")) GTEST_SKIP() << "needs the OpenCL tracer";
  size_t ahead = 0;
  for (const Band& b : render_three(false, true, &ahead)) EXPECT_EQ(b.result.balance_ms, 0.0) << "option off";
  EXPECT_EQ(ahead, 1u);
  for (const Band& b : render_three(true, false, &ahead)) EXPECT_EQ(b.result.balance_ms, 0.0) << "one in flight";
  EXPECT_EQ(ahead, 0u);
}
#endif
