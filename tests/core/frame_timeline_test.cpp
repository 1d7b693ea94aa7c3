#include "cohort/core/frame_timeline.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "cohort/core/renderer.h"
#include "cohort/core/simulated_tracer.h"

using namespace cohort::core;

namespace {

std::unique_ptr<Tracer> sim(uint64_t tag, SimulatedClock clock = SimulatedClock::sleep) {
  SimulatedTracerOptions o;
  o.name = "sim" + std::to_string(tag);
  o.seed = tag;
  o.clock = clock;
  o.time_scale = 0.05;  // a few real milliseconds per band
  if (tag == 2) o.throw_on_frames = {3};
  return std::make_unique<SimulatedTracer>(std::make_shared<SpinSceneCostModel>(3), o);
}

BandJob job_for(uint64_t frame) {
  BandJob job;
  job.camera = spin_camera(8, 64, 0.1 * static_cast<double>(frame));
  job.params.frame_index = static_cast<kuint>(frame);
  return job;
}

// The first span of a track whose stage starts with `stage` ("apply" also finds "apply (full resync)").
const StageSpan* find(const std::vector<StageSpan>& spans, const std::string& track, const std::string& stage) {
  for (const StageSpan& s : spans)
    if (s.track == track && s.stage.rfind(stage, 0) == 0) return &s;
  return nullptr;
}

}  // namespace

TEST(FrameTimeline, ScopedStageTimesItsScopeOnTheSharedClock) {
  std::vector<StageSpan> spans;
  const double before = timeline_now_ms();
  {
    ScopedStage stage(spans, kCoreTrack, "tone map");
    std::this_thread::sleep_for(std::chrono::milliseconds(3));
  }
  const double after = timeline_now_ms();
  ASSERT_EQ(spans.size(), 1u);
  EXPECT_EQ(spans[0].stage, "tone map");
  EXPECT_GE(spans[0].start_ms, before);
  EXPECT_GE(spans[0].ms, 3.0);
  EXPECT_LE(spans[0].start_ms + spans[0].ms, after + 1e-6);
}

TEST(FrameTimeline, RendererRecordsEveryTracersApplyAndRenderAndTheCoresStages) {
  std::vector<std::unique_ptr<Tracer>> tracers;
  tracers.push_back(sim(1));
  tracers.push_back(sim(2));
  Renderer renderer(std::move(tracers), RendererOptions{});
  auto scene = std::make_shared<cohort::commit::TracerScene>();
  FrameBuffer fb;
  for (uint64_t f = 0; f < 5; ++f) {
    if (f == 0) renderer.submit_commit(cohort::commit::CommitBuffer::full(scene, 0));
    cohort::commit::CommitBuffer commit;
    commit.set_frame(f + 1);
    commit.set_camera(job_for(f).camera);
    renderer.submit_commit(commit, [&] { return scene; });
    const FrameStats stats = renderer.render(job_for(f), fb);
    const double end = stats.start_ms + stats.wall_ms;
    EXPECT_NE(find(stats.stages, kCoreTrack, "balance"), nullptr) << "frame " << f;
    EXPECT_NE(find(stats.stages, kCoreTrack, "merge"), nullptr) << "frame " << f;
    for (const TracerFrameStats& t : stats.tracers) {
      const std::string track = tracer_track(t.id, t.name);
      const StageSpan* apply = find(stats.stages, track, "apply");
      const StageSpan* render = find(stats.stages, track, "render");
      if (t.outcome == TracerOutcome::threw) continue;  // its spans arrive with the failure, not the merge
      ASSERT_NE(apply, nullptr) << track << " frame " << f;
      ASSERT_NE(render, nullptr) << track << " frame " << f;
      EXPECT_LE(apply->start_ms + apply->ms, render->start_ms + 1e-3);  // commits first, then the band
      EXPECT_NEAR(apply->ms + render->ms, t.ms, 0.5);                   // the tracer's cost is both
      if (f == 0) { EXPECT_EQ(apply->stage, "apply (full resync)"); }
    }
    for (const StageSpan& s : stats.stages) {
      EXPECT_GE(s.start_ms, stats.start_ms - 1e-3) << s.track << " " << s.stage;
      EXPECT_LE(s.start_ms + s.ms, end + 1e-3) << s.track << " " << s.stage;
    }
    if (f == 3) {  // sim2 threw: the survivor re-renders its rows, and that shows as its own stage
      EXPECT_NE(find(stats.stages, tracer_track(0, "sim1"), "re-render"), nullptr);
    }
  }
}

TEST(FrameTimeline, ChromeTraceIsAJsonArrayOfCompleteEventsWithNamedThreads) {
  const auto path = std::filesystem::temp_directory_path() / ("cohort_trace_" + std::to_string(::getpid()) + ".json");
  {
    ChromeTraceWriter trace(path.string());
    trace.add(7, {{kCoreTrack, "balance", 10.0, 0.5}, {tracer_track(0, "embree"), "render", 10.5, 4.0}});
    trace.add(8, {{tracer_track(1, "cuda:0"), "render", 15.0, 2.0}});
  }
  std::ifstream in(path);
  const nlohmann::json events = nlohmann::json::parse(in);
  std::filesystem::remove(path);
  ASSERT_TRUE(events.is_array());
  std::map<int, std::string> thread_names;
  std::vector<nlohmann::json> complete;
  for (const auto& e : events) {
    if (e["ph"] == "M" && e["name"] == "thread_name") thread_names[e["tid"].get<int>()] = e["args"]["name"];
    if (e["ph"] == "X") complete.push_back(e);
  }
  ASSERT_EQ(complete.size(), 3u);
  EXPECT_EQ(thread_names[complete[0]["tid"].get<int>()], "core");
  EXPECT_EQ(thread_names[complete[1]["tid"].get<int>()], "tracer 0 (embree)");
  EXPECT_EQ(thread_names[complete[2]["tid"].get<int>()], "tracer 1 (cuda:0)");
  EXPECT_DOUBLE_EQ(complete[1]["ts"].get<double>(), 10500.0);  // microseconds
  EXPECT_DOUBLE_EQ(complete[1]["dur"].get<double>(), 4000.0);
  EXPECT_EQ(complete[2]["args"]["frame"], 8);
}

TEST(FrameTimeline, ChromeTraceWriterNamesAFileItCannotWrite) {
  try {
    ChromeTraceWriter trace("/nonexistent-folder/trace.json");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-folder/trace.json"), std::string::npos);
  }
}

namespace {

// A tracer that reports its own clock as a GPU does: 1 ms of kernels and 0.5 ms of transfer in a band
// whose wall time is longer (the host's launches and waits around them).
class DeviceTimedTracer final : public Tracer {
 public:
  std::string name() const override { return "timed"; }
  void apply(const cohort::commit::CommitBuffer&) override {}
  BandResult render_band(const BandJob&, BandBuffer&) override {
    std::this_thread::sleep_for(std::chrono::milliseconds(4));
    BandResult result;
    result.device_ms = 1.0;
    result.transfer_ms = 0.5;
    return result;
  }
  using Tracer::render_band;
};

}  // namespace

TEST(FrameTimeline, AGpusOwnClockShowsItsKernelsAndTransferAtTheEndOfItsRender) {
  std::vector<std::unique_ptr<Tracer>> tracers;
  tracers.push_back(std::make_unique<DeviceTimedTracer>());
  tracers.push_back(sim(1));
  Renderer renderer(std::move(tracers), RendererOptions{});
  renderer.submit_commit(cohort::commit::CommitBuffer::full(std::make_shared<cohort::commit::TracerScene>(), 0));
  FrameBuffer fb;
  const FrameStats stats = renderer.render(job_for(0), fb);
  const std::string timed = tracer_track(0, "timed");
  const StageSpan* render = find(stats.stages, timed, "render");
  const StageSpan* kernels = find(stats.stages, timed, "kernels");
  const StageSpan* transfer = find(stats.stages, timed, "transfer");
  ASSERT_NE(render, nullptr);
  ASSERT_NE(kernels, nullptr);
  ASSERT_NE(transfer, nullptr);
  EXPECT_NEAR(kernels->ms, 1.0, 1e-9);
  EXPECT_NEAR(transfer->ms, 0.5, 1e-9);
  EXPECT_NEAR(transfer->start_ms + transfer->ms, render->start_ms + render->ms, 1e-9) << "the transfer ends the band";
  EXPECT_NEAR(kernels->start_ms + kernels->ms, transfer->start_ms, 1e-9) << "the kernels end where it begins";
  EXPECT_EQ(find(stats.stages, tracer_track(1, "sim1"), "kernels"), nullptr) << "a tracer that cannot tell has none";
}

TEST(FrameTimeline, StagesOnAnotherClockEndAtTheGivenTimeBackToBackAndNeverBeforeTheBound) {
  std::vector<StageSpan> spans;
  append_spans_ending_at(spans, "gpu", 100.0, {{"upload", 1.0}, {"passes", 2.0}, {"download", 0.5}});
  ASSERT_EQ(spans.size(), 3u);
  EXPECT_EQ(spans[0].stage, "upload");
  EXPECT_DOUBLE_EQ(spans[0].start_ms, 96.5);
  EXPECT_DOUBLE_EQ(spans[1].start_ms, 97.5);
  EXPECT_DOUBLE_EQ(spans[2].start_ms, 99.5);
  EXPECT_DOUBLE_EQ(spans[2].start_ms + spans[2].ms, 100.0);
  EXPECT_DOUBLE_EQ(spans[0].ms + spans[1].ms + spans[2].ms, 3.5);
  spans.clear();
  append_spans_ending_at(spans, "gpu", 10.0, {{"kernels", 5.0}, {"transfer", 1.0}}, 7.0);
  EXPECT_DOUBLE_EQ(spans[0].start_ms, 7.0) << "clipped to the bound";
  EXPECT_DOUBLE_EQ(spans[0].ms, 2.0);
  EXPECT_DOUBLE_EQ(spans[1].start_ms, 9.0);
  EXPECT_DOUBLE_EQ(spans[1].ms, 1.0);
}
