#include "cohort/core/frame_pipeline.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <condition_variable>
#include <map>
#include <mutex>
#include <thread>

#include "cohort/core/simulated_tracer.h"

using namespace cohort::core;

namespace {

constexpr int kWidth = 8, kRows = 64;

std::unique_ptr<Tracer> sleeping_tracer(uint64_t tag) {
  SimulatedTracerOptions o;
  o.name = "sim" + std::to_string(tag);
  o.seed = tag;
  o.clock = SimulatedClock::sleep;
  o.time_scale = 24.0;  // a band takes some 60 ms of real time: far longer than the core's stages here
  return std::make_unique<SimulatedTracer>(std::make_shared<SpinSceneCostModel>(3), o);
}

BandJob job_for(uint64_t frame) {
  BandJob job;
  job.camera = spin_camera(kWidth, kRows, 0.05 * static_cast<double>(frame));
  job.params.frame_index = static_cast<kuint>(frame);
  return job;
}

// Lets the test decide when a frame's bands may finish: a tracer rendering frame f waits until the test
// opens frame f's gate. The test opens it only after it has done the core's work that must overlap that
// frame, so the overlap is certain by construction, whatever the scheduler does; a serial pipeline would
// wait on a gate that opens only later, and the tracer would give up after kPatience.
struct FrameGates {
  static constexpr auto kPatience = std::chrono::seconds(5);
  std::mutex mutex;
  std::condition_variable opened;
  int64_t open_through = -1;
  bool gave_up = false;

  void open(uint64_t frame) {
    std::lock_guard lock(mutex);
    open_through = std::max(open_through, static_cast<int64_t>(frame));
    opened.notify_all();
  }
  void wait(uint64_t frame) {
    std::unique_lock lock(mutex);
    if (!opened.wait_for(lock, kPatience, [&] { return open_through >= static_cast<int64_t>(frame); })) gave_up = true;
  }
};

// Fills its band with the frame index once the frame's gate is open.
class GatedTracer final : public Tracer {
 public:
  GatedTracer(std::string name, std::shared_ptr<FrameGates> gates) : name_(std::move(name)), gates_(std::move(gates)) {}
  std::string name() const override { return name_; }
  void apply(const cohort::commit::CommitBuffer&) override {}
  using Tracer::render_band;
  BandResult render_band(const BandJob& job, BandBuffer& target) override {
    gates_->wait(job.params.frame_index);
    std::vector<float> row(static_cast<size_t>(target.width()) * 4, static_cast<float>(job.params.frame_index));
    for (kuint y = job.params.row_begin; y < job.params.row_end; ++y)
      target.store(static_cast<int>(y), 0, row.data(), static_cast<size_t>(target.width()));
    return {};
  }

 private:
  std::string name_;
  std::shared_ptr<FrameGates> gates_;
};

std::vector<StageSpan> spans_of(const FrameStats& stats, const std::string& stage, bool tracers) {
  std::vector<StageSpan> out;
  for (const StageSpan& s : stats.stages)
    if (s.stage == stage && (s.track != kCoreTrack) == tracers) out.push_back(s);
  return out;
}

// The core's span of `stage` in a frame starts while another frame is in flight: after that frame's bands
// were handed out ("balance") and before its last band finished rendering.
bool core_stage_starts_while_in_flight(const FrameStats& core_frame, const std::string& stage,
                                       const FrameStats& in_flight) {
  const std::vector<StageSpan> handout = spans_of(in_flight, "balance", false);
  const std::vector<StageSpan> renders = spans_of(in_flight, "render", true);
  if (handout.empty() || renders.empty()) return false;
  double last_render_end = 0.0;
  for (const StageSpan& r : renders) last_render_end = std::max(last_render_end, r.start_ms + r.ms);
  for (const StageSpan& c : spans_of(core_frame, stage, false))
    if (c.start_ms >= handout.front().start_ms && c.start_ms < last_render_end) return true;
  return false;
}

}  // namespace

TEST(FramePipeline, TheCorePreparesTheNextFrameAndFinishesThePreviousOneWhileTheTracersRender) {
  auto gates = std::make_shared<FrameGates>();
  std::vector<std::unique_ptr<Tracer>> tracers;
  tracers.push_back(std::make_unique<GatedTracer>("gated1", gates));
  tracers.push_back(std::make_unique<GatedTracer>("gated2", gates));
  Renderer renderer(std::move(tracers), RendererOptions{});
  FramePipeline pipeline(renderer);
  auto scene = std::make_shared<cohort::commit::TracerScene>();
  renderer.submit_commit(cohort::commit::CommitBuffer::full(scene, 0));

  std::map<uint64_t, FrameStats> frames;
  auto finish = [&](FramePipeline::Delivered done) {
    // Everything is delivered whole: every row comes from this frame.
    for (int y = 0; y < kRows; ++y) ASSERT_EQ(pipeline.image().row(y)[0], static_cast<float>(done.stats.frame));
    ScopedStage tone_mapping(done.stats.stages, kCoreTrack, "tone map");  // stands for blend, tone map, output
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    tone_mapping.finish();
    frames[done.stats.frame] = std::move(done.stats);
  };
  constexpr uint64_t kFrames = 6;
  for (uint64_t f = 0; f < kFrames; ++f) {
    std::vector<StageSpan> preparation;
    ScopedStage syncing(preparation, kCoreTrack, "world sync");  // stands for WorldSync folding the changes
    cohort::commit::CommitBuffer commit;
    commit.set_frame(f + 1);
    commit.set_camera(job_for(f).camera);
    renderer.submit_commit(commit, [&] { return scene; });
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    syncing.finish();
    if (f > 0) gates->open(f - 1);  // frame f-1 may finish now that frame f's world sync has run
    std::optional<FramePipeline::Delivered> done = pipeline.push(job_for(f), std::move(preparation));
    ASSERT_EQ(done.has_value(), f > 0);
    if (done) {
      EXPECT_EQ(done->stats.frame, f - 1) << "one frame of latency";
      EXPECT_EQ(done->job.params.frame_index, f - 1);
      finish(std::move(*done));
    }
  }
  gates->open(kFrames - 1);
  std::optional<FramePipeline::Delivered> last = pipeline.drain();
  ASSERT_TRUE(last.has_value());
  EXPECT_FALSE(gates->gave_up) << "a tracer waited for core work that the pipeline did not let run alongside it";
  finish(std::move(*last));
  EXPECT_FALSE(pipeline.drain().has_value());
  ASSERT_EQ(frames.size(), kFrames);

  for (uint64_t n = 0; n + 1 < kFrames; ++n) {
    const FrameStats &now = frames[n], &next = frames[n + 1];
    EXPECT_TRUE(core_stage_starts_while_in_flight(next, "world sync", now)) << "world sync of " << n + 1 << " vs render of " << n;
    EXPECT_TRUE(core_stage_starts_while_in_flight(now, "merge", next)) << "merge of " << n << " vs render of " << n + 1;
    EXPECT_TRUE(core_stage_starts_while_in_flight(now, "tone map", next)) << "tone map of " << n << " vs render of " << n + 1;
    // The commit submitted while frame n rendered was applied before frame n+1's band, not n's.
    for (const StageSpan& apply : spans_of(next, "apply", true))
      EXPECT_GE(apply.start_ms, spans_of(next, "world sync", false).at(0).start_ms);
  }
}

TEST(FramePipeline, CallsOutOfOrderAreRefused) {
  std::vector<std::unique_ptr<Tracer>> tracers;
  tracers.push_back(sleeping_tracer(1));
  Renderer renderer(std::move(tracers), RendererOptions{});
  FrameBuffer a, b;
  EXPECT_THROW(renderer.wait_frame(), std::logic_error);
  renderer.begin_frame(job_for(3), a);
  EXPECT_THROW(renderer.begin_frame(job_for(4), b), std::logic_error);  // frame 3 not waited for
  FrameStats three = renderer.wait_frame();
  renderer.begin_frame(job_for(4), b);
  EXPECT_THROW(renderer.wait_frame(), std::logic_error);  // frame 3 not merged
  renderer.merge_frame(three);
  EXPECT_THROW(renderer.merge_frame(three), std::logic_error);
  FrameStats four = renderer.finish_frame();
  EXPECT_EQ(a.row(0)[0], 3.0f);
  EXPECT_EQ(b.row(kRows - 1)[0], 4.0f);
  EXPECT_EQ(four.frame, 4u);
}
