// Two frames in flight (RendererOptions::frames_in_flight = 2): frame N+1's jobs are handed out before N is
// waited for, queue behind N's on each worker, and every frame is still delivered whole, in order, with its
// own bands, faults recovered and shutdown prompt.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <future>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "cohort/core/frame_pipeline.h"
#include "cohort/core/renderer.h"
#include "cohort/core/simulated_tracer.h"

using namespace cohort::core;

namespace {

constexpr int kWidth = 8, kRows = 64;

BandJob job_for(uint64_t frame) {
  BandJob job;
  job.camera = spin_camera(kWidth, kRows, 0.05 * static_cast<double>(frame));
  job.params.frame_index = static_cast<kuint>(frame);
  return job;
}

RendererOptions two_in_flight() {
  RendererOptions options;
  options.frames_in_flight = 2;
  return options;
}

// Renders a frame only once the test opens its gate, and notes the frames it rendered, in order.
struct Gates {
  std::mutex mutex;
  std::condition_variable cv;
  int64_t open_through = -1;
  void open(uint64_t frame) {
    std::lock_guard lock(mutex);
    open_through = std::max(open_through, static_cast<int64_t>(frame));
    cv.notify_all();
  }
  bool wait(uint64_t frame, std::chrono::milliseconds patience) {
    std::unique_lock lock(mutex);
    return cv.wait_for(lock, patience, [&] { return open_through >= static_cast<int64_t>(frame); });
  }
};

class GatedTracer final : public Tracer {
 public:
  GatedTracer(std::string name, std::shared_ptr<Gates> gates, std::chrono::milliseconds patience = std::chrono::seconds(5))
      : name_(std::move(name)), gates_(std::move(gates)), patience_(patience) {}
  std::string name() const override { return name_; }
  void apply(const cohort::commit::CommitBuffer& commit) override {
    std::lock_guard lock(mutex_);
    commits_.push_back(commit.frame());
  }
  using Tracer::render_band;
  BandResult render_band(const BandJob& job, BandBuffer& target) override {
    if (!gates_->wait(job.params.frame_index, patience_)) throw std::runtime_error("gate never opened");
    std::vector<float> row(static_cast<size_t>(target.width()) * 4, static_cast<float>(job.params.frame_index));
    for (kuint y = job.params.row_begin; y < job.params.row_end; ++y)
      target.store(static_cast<int>(y), 0, row.data(), static_cast<size_t>(target.width()));
    std::lock_guard lock(mutex_);
    rendered_.push_back(job.params.frame_index);
    return {};
  }
  std::vector<uint64_t> rendered() const {
    std::lock_guard lock(mutex_);
    return rendered_;
  }
  std::vector<uint64_t> commits() const {
    std::lock_guard lock(mutex_);
    return commits_;
  }

 private:
  std::string name_;
  std::shared_ptr<Gates> gates_;
  std::chrono::milliseconds patience_;
  mutable std::mutex mutex_;
  std::vector<uint64_t> rendered_;
  std::vector<uint64_t> commits_;
};

// Enqueues ahead (Tracer::enqueues_ahead), as the OpenCL tracer does: inside each band, once its rows are
// written, it asks for its queued next job until the band's time is up, and "enqueues" it (writes that job's
// rows into that job's target at once). Notes in order every commit applied, band rendered and job taken ahead.
struct AheadLog {
  std::mutex mutex;
  std::vector<std::string> events;
  int dropped = 0;
  std::promise<void> took_ahead;  // set the first time a job is taken ahead
  bool signalled = false;
  void note(const std::string& event) {
    std::lock_guard lock(mutex);
    events.push_back(event);
  }
  std::vector<std::string> taken() {
    std::lock_guard lock(mutex);
    return events;
  }
};

class AheadTracer final : public Tracer {
 public:
  AheadTracer(std::shared_ptr<AheadLog> log, std::chrono::milliseconds band_time)
      : log_(std::move(log)), band_time_(band_time) {}
  std::string name() const override { return "ahead"; }
  bool enqueues_ahead() const override { return true; }
  void apply(const cohort::commit::CommitBuffer& commit) override { log_->note("apply " + std::to_string(commit.frame())); }
  using Tracer::render_band;
  BandResult render_band(const BandJob& job, BandBuffer& target) override {
    const kuint frame = job.params.frame_index;
    if (!ahead_ || ahead_->job.params.frame_index != frame || ahead_->target != &target) write_rows(job, target);
    ahead_.reset();
    log_->note("render " + std::to_string(frame));
    const auto band_end = std::chrono::steady_clock::now() + band_time_;
    if (std::optional<QueuedNext> next = queued_next([&] { return std::chrono::steady_clock::now() >= band_end; })) {
      log_->note("ahead " + std::to_string(next->job.params.frame_index));
      if (next->target == &target) log_->note("same target");
      write_rows(next->job, *next->target);
      ahead_ = next;
      std::lock_guard lock(log_->mutex);
      if (!log_->signalled) log_->took_ahead.set_value();
      log_->signalled = true;
    }
    std::this_thread::sleep_until(band_end);
    return {};
  }
  void drop_enqueued_ahead() override {
    ahead_.reset();
    std::lock_guard lock(log_->mutex);
    ++log_->dropped;
  }

 private:
  static void write_rows(const BandJob& job, BandBuffer& target) {
    std::vector<float> row(static_cast<size_t>(target.width()) * 4, static_cast<float>(job.params.frame_index));
    for (kuint y = job.params.row_begin; y < job.params.row_end; ++y)
      target.store(static_cast<int>(y), 0, row.data(), static_cast<size_t>(target.width()));
  }
  std::shared_ptr<AheadLog> log_;
  std::chrono::milliseconds band_time_;
  std::optional<QueuedNext> ahead_;
};

void submit_frame_commit(Renderer& renderer, uint64_t frame, const std::shared_ptr<cohort::commit::TracerScene>& scene) {
  if (frame == 0) {
    renderer.submit_commit(cohort::commit::CommitBuffer::full(scene, 0));
    return;
  }
  cohort::commit::CommitBuffer records;
  records.set_frame(frame);
  records.set_camera(job_for(frame).camera);
  renderer.submit_commit(records, [scene] { return scene; });
}

void expect_every_row_of_frame(const FrameBuffer& image, uint64_t frame) {
  for (int y = 0; y < image.height; ++y)
    ASSERT_EQ(image.row(y)[0], static_cast<float>(frame)) << "row " << y << " of frame " << frame;
}

}  // namespace

TEST(FramesInFlight, AWorkerWithTwoQueuedJobsRendersThemInOrderWithTheirOwnCommits) {
  auto gates = std::make_shared<Gates>();
  std::vector<std::unique_ptr<Tracer>> tracers;
  tracers.push_back(std::make_unique<GatedTracer>("gated1", gates));
  tracers.push_back(std::make_unique<GatedTracer>("gated2", gates));
  auto* first = static_cast<GatedTracer*>(tracers[0].get());
  Renderer renderer(std::move(tracers), two_in_flight());
  auto scene = std::make_shared<cohort::commit::TracerScene>();
  FrameBuffer image0, image1;
  submit_frame_commit(renderer, 0, scene);
  renderer.begin_frame(job_for(0), image0);
  submit_frame_commit(renderer, 1, scene);
  // Frame 0 cannot end before its gate opens: frame 1 is handed out while it is in flight.
  renderer.begin_frame(job_for(1), image1);
  EXPECT_EQ(renderer.frames_begun(), 2);
  EXPECT_THROW(renderer.begin_frame(job_for(2), image0), std::logic_error) << "never a third frame";
  EXPECT_THROW(renderer.render(job_for(2), image0), std::logic_error) << "render() needs no frame in flight";
  gates->open(1);
  FrameStats stats0 = renderer.wait_frame();
  renderer.merge_frame(stats0);
  EXPECT_EQ(stats0.frame, 0u);
  expect_every_row_of_frame(image0, 0);
  FrameStats stats1 = renderer.wait_frame();
  renderer.merge_frame(stats1);
  EXPECT_EQ(stats1.frame, 1u);
  expect_every_row_of_frame(image1, 1);
  EXPECT_EQ(first->rendered(), (std::vector<uint64_t>{0, 1}));
  // Frame 1's commit was taken at its hand-out, while frame 0's may still have been applied: each came
  // with its own job, in order.
  EXPECT_EQ(first->commits(), (std::vector<uint64_t>{0, 1}));
  for (const FrameStats* stats : {&stats0, &stats1})
    for (const TracerFrameStats& t : stats->tracers) EXPECT_EQ(t.outcome, TracerOutcome::rendered) << "frame " << stats->frame;
}

TEST(FramesInFlight, ThePipelineHandsTheNextFrameOutBeforeItWaitsAndDeliversEveryFrameWholeWithItsOwnBands) {
  std::vector<std::unique_ptr<Tracer>> tracers;
  for (uint64_t tag : {1, 2}) {
    SimulatedTracerOptions o;
    o.name = "sim" + std::to_string(tag);
    o.seed = tag;
    o.speed = tag == 1 ? 3.0 : 1.0;
    o.clock = SimulatedClock::sleep;
    o.time_scale = 4.0;
    tracers.push_back(std::make_unique<SimulatedTracer>(std::make_shared<SpinSceneCostModel>(3), o));
  }
  Renderer renderer(std::move(tracers), two_in_flight());
  FramePipeline pipeline(renderer);
  auto scene = std::make_shared<cohort::commit::TracerScene>();
  std::vector<FrameStats> delivered;
  auto take = [&](std::optional<FramePipeline::Delivered> done) {
    if (!done) return;
    // SimulatedTracer writes (frame, tag): every row of this frame, from a tracer with a claim on it.
    for (int y = 0; y < kRows; ++y) {
      const float* p = pipeline.image().row(y);
      ASSERT_EQ(p[0], static_cast<float>(done->stats.frame)) << "row " << y;
      const TracerFrameStats& owner = done->stats.tracers[static_cast<size_t>(p[1]) - 1];
      EXPECT_TRUE(y >= owner.row_begin && y < owner.row_end) << "row " << y << " of frame " << done->stats.frame;
    }
    delivered.push_back(std::move(done->stats));
  };
  constexpr uint64_t kFrames = 12;
  for (uint64_t f = 0; f < kFrames; ++f) {
    submit_frame_commit(renderer, f, scene);
    if (f == 5) renderer.reset_balancer();     // a camera cut between frames
    if (f == 8) renderer.set_balancer("perfect");
    take(pipeline.push(job_for(f)));
    EXPECT_EQ(renderer.frames_begun(), 1) << "after push, one frame in flight";
  }
  take(pipeline.drain());
  ASSERT_EQ(delivered.size(), kFrames);
  for (uint64_t f = 0; f < kFrames; ++f) EXPECT_EQ(delivered[f].frame, f);
  // Each band is its frame's: on a tracer's track frame f+1's render starts no earlier than frame f's ends,
  // and after frame f+1's hand-out.
  for (uint64_t f = 1; f + 1 < kFrames; ++f) {
    for (const TracerFrameStats& t : delivered[f].tracers) {
      if (t.outcome != TracerOutcome::rendered || delivered[f + 1].tracers[t.id].outcome != TracerOutcome::rendered) continue;
      const std::string track = tracer_track(t.id, t.name);
      auto render_of = [&](const FrameStats& s) -> const StageSpan* {
        for (const StageSpan& span : s.stages)
          if (span.track == track && span.stage == "render") return &span;
        return nullptr;
      };
      const StageSpan* now = render_of(delivered[f]);
      const StageSpan* next = render_of(delivered[f + 1]);
      ASSERT_NE(now, nullptr);
      ASSERT_NE(next, nullptr);
      EXPECT_GE(next->start_ms, now->start_ms + now->ms - 1e-3) << track << " frame " << f;
      EXPECT_GE(next->start_ms, delivered[f + 1].start_ms - 1e-3) << track << " frame " << f + 1;
    }
    // Idle with overlap: only the time a tracer had no job, at most the time between hand-outs.
    EXPECT_GE(delivered[f].idle_percent, 0.0);
    EXPECT_LE(delivered[f].idle_percent, 100.0);
  }
  // The slow tracer never waits for the core: with its next job queued its idle stays near zero.
  double slow_idle = 0.0;
  for (uint64_t f = 4; f < kFrames; ++f) slow_idle += delivered[f].tracers[1].idle_ms;
  EXPECT_LT(slow_idle / (kFrames - 4), 2.0) << "ms a frame without a job";
}

TEST(FramesInFlight, AFailingTracersRowsAreReRenderedWithTwoFramesInFlight) {
  std::vector<std::unique_ptr<Tracer>> tracers;
  for (uint64_t tag : {1, 2, 3}) {
    SimulatedTracerOptions o;
    o.name = "sim" + std::to_string(tag);
    o.seed = tag;
    o.clock = SimulatedClock::sleep;
    if (tag == 2) o.throw_on_frames = {3, 4};
    tracers.push_back(std::make_unique<SimulatedTracer>(std::make_shared<SpinSceneCostModel>(3), o));
  }
  Renderer renderer(std::move(tracers), two_in_flight());
  FramePipeline pipeline(renderer);
  auto scene = std::make_shared<cohort::commit::TracerScene>();
  std::map<uint64_t, FrameStats> frames;
  auto take = [&](std::optional<FramePipeline::Delivered> done) {
    if (!done) return;
    for (int y = 0; y < kRows; ++y)
      ASSERT_EQ(pipeline.image().row(y)[0], static_cast<float>(done->stats.frame)) << "row " << y;
    frames[done->stats.frame] = std::move(done->stats);
  };
  for (uint64_t f = 0; f < 8; ++f) {
    submit_frame_commit(renderer, f, scene);
    take(pipeline.push(job_for(f)));
  }
  take(pipeline.drain());
  ASSERT_EQ(frames.size(), 8u);
  for (uint64_t f : {3, 4}) {
    const FrameStats& s = frames[f];
    EXPECT_EQ(s.tracers[1].outcome, TracerOutcome::threw) << "frame " << f;
    EXPECT_EQ(s.tracers[0].recovery_rows + s.tracers[2].recovery_rows, s.tracers[1].row_end - s.tracers[1].row_begin)
        << "frame " << f;
  }
  EXPECT_EQ(frames[6].tracers[1].outcome, TracerOutcome::rendered) << "it rejoins";
}

TEST(FramesInFlight, AStalledTracersRowsAreReRenderedAndItRejoinsWithoutDeadlock) {
  auto gates = std::make_shared<Gates>();
  std::vector<std::unique_ptr<Tracer>> tracers;
  SimulatedTracerOptions quick;
  quick.name = "sim1";
  tracers.push_back(std::make_unique<SimulatedTracer>(std::make_shared<SpinSceneCostModel>(3), quick));
  SimulatedTracerOptions stalling = quick;
  stalling.name = "sim2";
  stalling.seed = 2;
  stalling.hang_on_frames = {2};
  stalling.hang_ms = 150.0;
  tracers.push_back(std::make_unique<SimulatedTracer>(std::make_shared<SpinSceneCostModel>(3), stalling));
  RendererOptions options = two_in_flight();
  options.frame_timeout = std::chrono::milliseconds(100);
  Renderer renderer(std::move(tracers), options);
  FramePipeline pipeline(renderer);
  auto scene = std::make_shared<cohort::commit::TracerScene>();
  std::map<uint64_t, FrameStats> frames;
  auto take = [&](std::optional<FramePipeline::Delivered> done) {
    if (!done) return;
    for (int y = 0; y < kRows; ++y) ASSERT_EQ(pipeline.image().row(y)[0], static_cast<float>(done->stats.frame));
    frames[done->stats.frame] = std::move(done->stats);
  };
  for (uint64_t f = 0; f < 14; ++f) {
    submit_frame_commit(renderer, f, scene);
    take(pipeline.push(job_for(f)));
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  take(pipeline.drain());
  ASSERT_EQ(frames.size(), 14u) << "every frame delivered whole";
  EXPECT_EQ(frames[2].tracers[1].outcome, TracerOutcome::timed_out);
  // Its job of frame 3 queued behind the stalled one: that frame may lose it too, and it rejoins later.
  EXPECT_EQ(frames[13].tracers[1].outcome, TracerOutcome::rendered);
}

TEST(FramesInFlight, ShutdownWithTwoFramesInFlightDoesNotHang) {
  auto gates = std::make_shared<Gates>();  // never opened: every band waits until its patience runs out
  std::vector<std::unique_ptr<Tracer>> tracers;
  tracers.push_back(std::make_unique<GatedTracer>("gated1", gates, std::chrono::milliseconds(300)));
  tracers.push_back(std::make_unique<GatedTracer>("gated2", gates, std::chrono::milliseconds(300)));
  RendererOptions options = two_in_flight();
  options.shutdown_timeout = std::chrono::milliseconds(2000);
  auto renderer = std::make_unique<Renderer>(std::move(tracers), options);
  auto scene = std::make_shared<cohort::commit::TracerScene>();
  FrameBuffer image0, image1;
  submit_frame_commit(*renderer, 0, scene);
  renderer->begin_frame(job_for(0), image0);
  renderer->begin_frame(job_for(1), image1);
  const auto start = std::chrono::steady_clock::now();
  auto closed = std::async(std::launch::async, [&] { renderer.reset(); });
  ASSERT_EQ(closed.wait_for(std::chrono::seconds(10)), std::future_status::ready) << "shutdown hung";
  // The queued jobs of frame 1 were dropped: only the running bands of frame 0 were waited for.
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::milliseconds(1500));
}

// With two in flight a tracer that enqueues ahead gets its next job inside the band before, with that job's
// commit applied first, once; the job then brings no commit, every frame is delivered whole with its own
// rows, and with one in flight nothing is queued to take.
void expect_enqueued_ahead_in_order(int in_flight) {
  auto log = std::make_shared<AheadLog>();
  std::vector<std::unique_ptr<Tracer>> tracers;
  tracers.push_back(std::make_unique<AheadTracer>(log, std::chrono::milliseconds(15)));
  auto gates = std::make_shared<Gates>();
  gates->open(1000);  // a second tracer that never waits
  tracers.push_back(std::make_unique<GatedTracer>("open", gates));
  RendererOptions options;
  options.frames_in_flight = in_flight;
  Renderer renderer(std::move(tracers), options);
  FramePipeline pipeline(renderer);
  auto scene = std::make_shared<cohort::commit::TracerScene>();
  int delivered = 0;
  auto take = [&](std::optional<FramePipeline::Delivered> done) {
    if (!done) return;
    expect_every_row_of_frame(pipeline.image(), done->stats.frame);
    ++delivered;
  };
  constexpr uint64_t kFrames = 10;
  for (uint64_t f = 0; f < kFrames; ++f) {
    submit_frame_commit(renderer, f, scene);
    take(pipeline.push(job_for(f)));
  }
  take(pipeline.drain());
  EXPECT_EQ(delivered, int(kFrames));
  const std::vector<std::string> events = log->taken();
  auto at = [&](const std::string& event) {
    const auto it = std::find(events.begin(), events.end(), event);
    EXPECT_EQ(std::count(events.begin(), events.end(), event), it == events.end() ? 0 : 1) << event << " twice";
    return it == events.end() ? -1 : static_cast<int>(it - events.begin());
  };
  int ahead = 0;
  for (uint64_t f = 0; f < kFrames; ++f) {
    const std::string n = std::to_string(f);
    const int applied = at("apply " + n), rendered = at("render " + n), taken = at("ahead " + n);
    ASSERT_GE(applied, 0) << "frame " << f << "'s commit was never applied";
    ASSERT_GE(rendered, 0);
    EXPECT_LT(applied, rendered) << "frame " << f;
    if (taken < 0) continue;
    ++ahead;
    EXPECT_EQ(applied + 1, taken) << "frame " << f << "'s commit is applied just before it is handed over";
    if (f > 0) {
      EXPECT_LT(at("render " + std::to_string(f - 1)), applied) << "inside the band before";
    }
  }
  EXPECT_EQ(std::count(events.begin(), events.end(), "same target"), 0) << "the next job renders into the other target";
  if (in_flight == 1) {
    EXPECT_EQ(ahead, 0);
  } else {
    EXPECT_GE(ahead, int(kFrames) / 2) << "the next job should be queued while most bands render";
  }
}

TEST(FramesInFlight, ATracerThatEnqueuesAheadGetsItsQueuedJobWithItsCommitAppliedOnce) { expect_enqueued_ahead_in_order(2); }
TEST(FramesInFlight, WithOneInFlightNothingIsEnqueuedAhead) { expect_enqueued_ahead_in_order(1); }

TEST(FramesInFlight, ShutdownDrainsAJobEnqueuedAheadThatWillNotRender) {
  auto log = std::make_shared<AheadLog>();
  std::future<void> took_ahead = log->took_ahead.get_future();
  std::vector<std::unique_ptr<Tracer>> tracers;
  tracers.push_back(std::make_unique<AheadTracer>(log, std::chrono::milliseconds(200)));
  RendererOptions options = two_in_flight();
  options.shutdown_timeout = std::chrono::milliseconds(5000);
  auto renderer = std::make_unique<Renderer>(std::move(tracers), options);
  auto scene = std::make_shared<cohort::commit::TracerScene>();
  FrameBuffer image0, image1;
  submit_frame_commit(*renderer, 0, scene);
  renderer->begin_frame(job_for(0), image0);
  submit_frame_commit(*renderer, 1, scene);
  renderer->begin_frame(job_for(1), image1);
  ASSERT_EQ(took_ahead.wait_for(std::chrono::seconds(10)), std::future_status::ready) << "frame 1 never taken ahead";
  renderer.reset();  // frame 1's job is dropped while frame 0's band still sleeps
  const std::vector<std::string> events = log->taken();
  EXPECT_EQ(std::count(events.begin(), events.end(), "render 1"), 0) << "a dropped job is not rendered";
  std::lock_guard lock(log->mutex);
  EXPECT_EQ(log->dropped, 1) << "the tracer is told to drain what it enqueued for the dropped job";
}

TEST(FramesInFlight, OnlyOneOrTwoFramesInFlight) {
  std::vector<std::unique_ptr<Tracer>> tracers;
  tracers.push_back(std::make_unique<SimulatedTracer>(std::make_shared<SpinSceneCostModel>(3), SimulatedTracerOptions{}));
  RendererOptions options;
  options.frames_in_flight = 3;
  EXPECT_THROW(Renderer(std::move(tracers), options), std::invalid_argument);
}
