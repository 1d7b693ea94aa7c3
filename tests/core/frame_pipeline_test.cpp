#include "cohort/core/frame_pipeline.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <condition_variable>
#include <cstring>
#include <cstdlib>
#include <functional>
#include <map>
#include <mutex>
#include <thread>

#include <nlohmann/json.hpp>

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
  // Until the frame's gate opens or `done()` (called every 200 us, first) says to stop waiting.
  template <typename Done>
  void poll(uint64_t frame, Done done) {
    const auto give_up = std::chrono::steady_clock::now() + kPatience;
    for (;;) {
      if (done()) return;
      {
        std::lock_guard lock(mutex);
        if (open_through >= static_cast<int64_t>(frame)) return;
      }
      if (std::chrono::steady_clock::now() > give_up) {
        gave_up = true;
        return;
      }
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
  }
  void wait(uint64_t frame) {
    if (!wait_for(frame, kPatience)) gave_up = true;
  }
  // Whether the frame's gate opened within `patience`.
  bool wait_for(uint64_t frame, std::chrono::milliseconds patience) {
    std::unique_lock lock(mutex);
    return opened.wait_for(lock, patience, [&] { return open_through >= static_cast<int64_t>(frame); });
  }
};

// Every pixel of the job's rows holds the frame index (what the pipeline tests read back).
void fill_band_with_frame_index(const BandJob& job, BandBuffer& target) {
  std::vector<float> row(static_cast<size_t>(target.width()) * 4, static_cast<float>(job.params.frame_index));
  for (kuint y = job.params.row_begin; y < job.params.row_end; ++y)
    target.store(static_cast<int>(y), 0, row.data(), static_cast<size_t>(target.width()));
}

// Which frames' bands have ended, per frame a count of the tracers done with it.
struct BandsEnded {
  std::mutex mutex;
  std::condition_variable cv;
  std::map<uint64_t, int> ended;
  void add(uint64_t frame) {
    std::lock_guard lock(mutex);
    ++ended[frame];
    cv.notify_all();
  }
  bool wait_for(uint64_t frame, int tracers, std::chrono::milliseconds patience) {
    std::unique_lock lock(mutex);
    return cv.wait_for(lock, patience, [&] { return ended[frame] >= tracers; });
  }
};

// Fills its band with the frame index once the frame's gate is open; says so in `ended` where given.
class GatedTracer final : public Tracer {
 public:
  GatedTracer(std::string name, std::shared_ptr<FrameGates> gates, std::shared_ptr<BandsEnded> ended = nullptr)
      : name_(std::move(name)), gates_(std::move(gates)), ended_(std::move(ended)) {}
  std::string name() const override { return name_; }
  void apply(const cohort::commit::CommitBuffer&) override {}
  using Tracer::render_band;
  BandResult render_band(const BandJob& job, BandBuffer& target) override {
    gates_->wait(job.params.frame_index);
    fill_band_with_frame_index(job, target);
    if (ended_) ended_->add(job.params.frame_index);
    return {};
  }

 private:
  std::string name_;
  std::shared_ptr<FrameGates> gates_;
  std::shared_ptr<BandsEnded> ended_;
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

namespace {

// Records, in order, each band's start and each commit applied, and whether a band was rendering then.
// With `ahead`, it takes commits ahead (Tracer::takes_commits_ahead, as a remote tracer does) while it
// waits for its frame's gate.
class CommitLoggingTracer final : public Tracer {
 public:
  struct Event {
    bool band = false;  // a band's start (frame: its frame index), else a commit applied (frame: the commit's)
    uint64_t frame = 0;
    bool during_band = false;
  };
  struct Log {
    std::mutex mutex;
    std::vector<Event> events;
    void add(Event e) {
      std::lock_guard lock(mutex);
      events.push_back(e);
    }
    std::vector<Event> read() {
      std::lock_guard lock(mutex);
      return events;
    }
  };
  CommitLoggingTracer(bool ahead, std::shared_ptr<FrameGates> gates, std::shared_ptr<Log> log)
      : ahead_(ahead), gates_(std::move(gates)), log_(std::move(log)) {}
  std::string name() const override { return ahead_ ? "ahead" : "with-job"; }
  bool takes_commits_ahead() const override { return ahead_; }
  void apply(const cohort::commit::CommitBuffer& commit) override {
    log_->add({false, commit.frame(), rendering_});
  }
  using Tracer::render_band;
  BandResult render_band(const BandJob& job, BandBuffer& target) override {
    log_->add({true, job.params.frame_index, false});
    rendering_ = true;
    gates_->poll(job.params.frame_index, [&] {
      apply_commits_ahead();
      return false;
    });
    rendering_ = false;
    fill_band_with_frame_index(job, target);
    return {};
  }

 private:
  bool ahead_;
  bool rendering_ = false;
  std::shared_ptr<FrameGates> gates_;
  std::shared_ptr<Log> log_;
};

// In a tracer's log, where commit `commit` was applied: the frame of the last band begun before it (-1:
// none) and whether that band was still rendering; (-2, false) if it never was.
std::pair<int64_t, bool> applied_before_band(const std::vector<CommitLoggingTracer::Event>& log, uint64_t commit) {
  int64_t last_band = -1;
  for (const auto& e : log) {
    if (e.band) last_band = static_cast<int64_t>(e.frame);
    else if (e.frame == commit) return {last_band, e.during_band};
  }
  return {-2, false};
}

// Two commit-logging tracers on one Renderer with `frames_in_flight`: the first takes commits ahead, the
// second with its job. The scene's full resync is submitted as frame 0's commit (number 0).
struct CommitsAheadPair {
  explicit CommitsAheadPair(int frames_in_flight) {
    std::vector<std::unique_ptr<Tracer>> tracers;
    tracers.push_back(std::make_unique<CommitLoggingTracer>(true, gates, ahead_log));
    tracers.push_back(std::make_unique<CommitLoggingTracer>(false, gates, job_log));
    RendererOptions options;
    options.balancer = "none";
    options.frames_in_flight = frames_in_flight;
    renderer = std::make_unique<Renderer>(std::move(tracers), options);
    renderer->submit_commit(cohort::commit::CommitBuffer::full(scene, 0));
  }
  // Frame f's commit, which carries frame number f + 1.
  void submit(uint64_t f) {
    cohort::commit::CommitBuffer commit;
    commit.set_frame(f + 1);
    commit.set_camera(job_for(f).camera);
    renderer->submit_commit(commit, [this] { return scene; });
  }
  // Over `frames` frames: each commit of frame f + 1 applied while frame f - 1's band rendered by the tracer
  // that takes commits ahead, after that band by the other; every commit reached both once, in order.
  void expect_each_commit_beside_the_band_before(uint64_t frames) const {
    const std::vector<CommitLoggingTracer::Event> ahead_events = ahead_log->read(), job_events = job_log->read();
    for (uint64_t f = 1; f < frames; ++f) {
      EXPECT_EQ(applied_before_band(ahead_events, f + 1), std::make_pair(static_cast<int64_t>(f) - 1, true)) << f;
      EXPECT_EQ(applied_before_band(job_events, f + 1), std::make_pair(static_cast<int64_t>(f) - 1, false)) << f;
    }
    std::vector<uint64_t> expected;
    for (uint64_t c = 1; c <= frames; ++c) expected.push_back(c);
    for (const auto* log : {&ahead_events, &job_events}) {
      std::vector<uint64_t> commits;
      for (const auto& e : *log)
        if (!e.band) commits.push_back(e.frame);
      EXPECT_EQ(commits, expected) << "every commit once, in order";
    }
  }

  std::shared_ptr<FrameGates> gates = std::make_shared<FrameGates>();
  std::shared_ptr<CommitLoggingTracer::Log> ahead_log = std::make_shared<CommitLoggingTracer::Log>();
  std::shared_ptr<CommitLoggingTracer::Log> job_log = std::make_shared<CommitLoggingTracer::Log>();
  std::shared_ptr<cohort::commit::TracerScene> scene = std::make_shared<cohort::commit::TracerScene>();
  std::unique_ptr<Renderer> renderer;
};

}  // namespace

TEST(FramePipeline, ATracerThatTakesCommitsAheadAppliesThemWhileItRendersTheOthersWithTheirNextJob) {
  CommitsAheadPair pair(1);
  FramePipeline pipeline(*pair.renderer);
  constexpr uint64_t kFrames = 6;
  uint64_t delivered = 0;
  for (uint64_t f = 0; f < kFrames; ++f) {
    // Frame f's commit (frame number f + 1) is submitted while frame f - 1 renders, as the core does.
    pair.submit(f);
    if (f > 0) {
      // The tracer that takes commits ahead has this one before frame f - 1 may finish.
      auto has_it = [&] {
        const auto events = pair.ahead_log->read();
        return !events.empty() && !events.back().band && events.back().frame == f + 1;
      };
      for (int i = 0; i < 5000 && !has_it(); ++i)
        std::this_thread::sleep_for(std::chrono::microseconds(200));
      pair.gates->open(f - 1);
    }
    if (std::optional<FramePipeline::Delivered> done = pipeline.push(job_for(f))) {
      for (int y = 0; y < kRows; ++y) ASSERT_EQ(pipeline.image().row(y)[0], static_cast<float>(done->stats.frame));
      EXPECT_EQ(done->stats.dropped, 0);
      ++delivered;
    }
  }
  pair.gates->open(kFrames - 1);
  ASSERT_TRUE(pipeline.drain().has_value());
  EXPECT_EQ(delivered + 1, kFrames);
  EXPECT_FALSE(pair.gates->gave_up);

  // Each log: the commit of frame f + 1 (with the full resync of frame 0 first) against the band starts:
  // ahead, applied while frame f - 1's band rendered, never under an earlier one; with its job, after frame
  // f - 1's band was done, before frame f's.
  pair.expect_each_commit_beside_the_band_before(kFrames);
  EXPECT_EQ(applied_before_band(pair.ahead_log->read(), 1), std::make_pair(int64_t(-1), false))
      << "the first commits come with the first job";
}

namespace {

// Records, for each band, the jobs announced while it rendered (Tracer::next_job_announced). With
// `ahead` it takes jobs ahead and waits, rendering, until the next frame's job is announced (or its
// frame's gate opens: the last frame has no next); otherwise it looks once and renders at once.
class AnnouncementTracer final : public Tracer {
 public:
  struct Seen {
    uint64_t band_frame = 0;
    std::vector<BandJob> announced;
  };
  AnnouncementTracer(bool ahead, std::shared_ptr<FrameGates> gates, std::shared_ptr<std::vector<Seen>> seen)
      : ahead_(ahead), gates_(std::move(gates)), seen_(std::move(seen)) {}
  std::string name() const override { return ahead_ ? "jobs-ahead" : "no-jobs-ahead"; }
  bool takes_jobs_ahead() const override { return ahead_; }
  void apply(const cohort::commit::CommitBuffer&) override {}
  using Tracer::render_band;
  BandResult render_band(const BandJob& job, BandBuffer& target) override {
    Seen seen{job.params.frame_index, {}};
    gates_->poll(job.params.frame_index, [&] {
      if (std::optional<BandJob> next = next_job_announced()) seen.announced.push_back(*next);
      return !ahead_ || !seen.announced.empty();
    });
    seen_->push_back(std::move(seen));
    fill_band_with_frame_index(job, target);
    return {};
  }

 private:
  bool ahead_;
  std::shared_ptr<FrameGates> gates_;
  std::shared_ptr<std::vector<Seen>> seen_;
};

}  // namespace

// With two frames in flight the next frame's job is queued behind the band before it is rendered: the
// tracer sees that one (its rows cleared, as an announcement has none).
static void expect_jobs_ahead_seen(int frames_in_flight) {
  auto gates = std::make_shared<FrameGates>();
  auto ahead_seen = std::make_shared<std::vector<AnnouncementTracer::Seen>>();
  auto other_seen = std::make_shared<std::vector<AnnouncementTracer::Seen>>();
  std::vector<std::unique_ptr<Tracer>> tracers;
  tracers.push_back(std::make_unique<AnnouncementTracer>(true, gates, ahead_seen));
  tracers.push_back(std::make_unique<AnnouncementTracer>(false, gates, other_seen));
  RendererOptions options;
  options.balancer = "none";
  options.frames_in_flight = frames_in_flight;
  Renderer renderer(std::move(tracers), options);
  FramePipeline pipeline(renderer);
  constexpr uint64_t kFrames = 6;
  for (uint64_t f = 0; f < kFrames; ++f) {
    if (std::optional<FramePipeline::Delivered> done = pipeline.push(job_for(f))) {
      for (int y = 0; y < kRows; ++y) ASSERT_EQ(pipeline.image().row(y)[0], static_cast<float>(done->stats.frame));
    }
  }
  gates->open(kFrames - 1);  // nothing is announced after the last frame
  ASSERT_TRUE(pipeline.drain().has_value());
  EXPECT_FALSE(gates->gave_up) << "a band of the tracer that takes jobs ahead never saw the next job announced";

  ASSERT_EQ(ahead_seen->size(), kFrames);
  for (const AnnouncementTracer::Seen& s : *ahead_seen) {
    if (s.band_frame + 1 == kFrames) {
      EXPECT_TRUE(s.announced.empty()) << "the last frame has no next";
      continue;
    }
    // Only the next frame's job, whole but for its rows, which are divided when it is handed out.
    ASSERT_FALSE(s.announced.empty()) << s.band_frame;
    for (const BandJob& next : s.announced) {
      const BandJob expected = job_for(s.band_frame + 1);
      EXPECT_EQ(next.params.frame_index, s.band_frame + 1);
      EXPECT_EQ(std::memcmp(&next.camera, &expected.camera, sizeof expected.camera), 0);
      EXPECT_EQ(next.params.row_begin, 0u);
      EXPECT_EQ(next.params.row_end, 0u);
    }
  }
  for (const AnnouncementTracer::Seen& s : *other_seen) EXPECT_TRUE(s.announced.empty()) << "it did not ask for jobs ahead";
}

TEST(FramePipeline, ATracerThatTakesJobsAheadSeesTheNextFramesJobWhileItRendersTheFrameBefore) {
  expect_jobs_ahead_seen(1);
}

TEST(FramePipeline, WithTwoFramesInFlightATracerThatTakesJobsAheadSeesItsQueuedJob) { expect_jobs_ahead_seen(2); }

TEST(FramePipeline, WithTwoFramesInFlightATracerThatTakesCommitsAheadAppliesItsQueuedJobsCommitInOrder) {
  CommitsAheadPair pair(2);
  Renderer& renderer = *pair.renderer;
  constexpr uint64_t kFrames = 6;
  FrameBuffer images[2];
  pair.submit(0);
  renderer.begin_frame(job_for(0), images[0]);
  for (uint64_t f = 1; f < kFrames; ++f) {
    pair.submit(f);
    // Handed out while frame f - 1 renders: the job holds frame f's commit, and the next commit, submitted
    // only after this hand-out, stays in the channel for the job after.
    renderer.begin_frame(job_for(f), images[f % 2]);
    auto has_it = [&] {
      for (const auto& e : pair.ahead_log->read())
        if (!e.band && e.frame == f + 1) return true;
      return false;
    };
    for (int i = 0; i < 5000 && !has_it(); ++i) std::this_thread::sleep_for(std::chrono::microseconds(200));
    pair.gates->open(f - 1);
    FrameStats stats = renderer.wait_frame();
    renderer.merge_frame(stats);
    EXPECT_EQ(stats.frame, f - 1);
    for (int y = 0; y < kRows; ++y) ASSERT_EQ(images[(f - 1) % 2].row(y)[0], static_cast<float>(f - 1));
  }
  pair.gates->open(kFrames - 1);
  FrameStats last = renderer.wait_frame();
  renderer.merge_frame(last);
  EXPECT_FALSE(pair.gates->gave_up);
  // The queued job's commit, applied while frame f - 1's band rendered.
  pair.expect_each_commit_beside_the_band_before(kFrames);
}

// `cohort play` announces at hand-out only where a tracer takes jobs ahead (it costs a frame of input
// latency): the Renderer says whether one does.
TEST(FramePipeline, TheRendererSaysWhetherATracerTakesJobsAhead) {
  auto gates = std::make_shared<FrameGates>();
  auto seen = std::make_shared<std::vector<AnnouncementTracer::Seen>>();
  for (bool ahead : {false, true}) {
    std::vector<std::unique_ptr<Tracer>> tracers;
    tracers.push_back(std::make_unique<AnnouncementTracer>(false, gates, seen));
    tracers.push_back(std::make_unique<AnnouncementTracer>(ahead, gates, seen));
    Renderer renderer(std::move(tracers), RendererOptions{});
    EXPECT_EQ(renderer.takes_jobs_ahead(), ahead);
  }
}

namespace {

// Takes jobs ahead; each band renders until the next frame's job is announced (or its frame's gate
// opens: the last frame has no next), then opens `saw_next`'s gate of its frame and keeps the job it saw.
class AheadWatcher final : public Tracer {
 public:
  AheadWatcher(std::shared_ptr<FrameGates> gates, std::shared_ptr<FrameGates> saw_next,
               std::shared_ptr<std::map<uint64_t, BandJob>> announced)
      : gates_(std::move(gates)), saw_next_(std::move(saw_next)), announced_(std::move(announced)) {}
  std::string name() const override { return "ahead-watcher"; }
  bool takes_jobs_ahead() const override { return true; }
  void apply(const cohort::commit::CommitBuffer&) override {}
  using Tracer::render_band;
  BandResult render_band(const BandJob& job, BandBuffer& target) override {
    std::optional<BandJob> next;
    gates_->poll(job.params.frame_index, [&] { return (next = next_job_announced()).has_value(); });
    if (next) {
      (*announced_)[job.params.frame_index] = *next;
      saw_next_->open(job.params.frame_index);
    }
    fill_band_with_frame_index(job, target);
    return {};
  }

 private:
  std::shared_ptr<FrameGates> gates_, saw_next_;
  std::shared_ptr<std::map<uint64_t, BandJob>> announced_;
};

}  // namespace

// push() with prepare_next announces the next frame as soon as this one is handed out: the band of frame
// f+1 sees f+2's job before push() returns frame f, so before the caller post-processes f (which here
// waits for exactly that; without prepare_next it would wait in vain, the announcement coming only with
// the next push, after the post).
TEST(FramePipeline, PrepareNextAnnouncesTheNextFrameBeforeTheFrameBeforeIsPostProcessed) {
  auto gates = std::make_shared<FrameGates>();
  auto saw_next = std::make_shared<FrameGates>();
  auto announced = std::make_shared<std::map<uint64_t, BandJob>>();
  std::vector<std::unique_ptr<Tracer>> tracers;
  tracers.push_back(std::make_unique<AheadWatcher>(gates, saw_next, announced));
  RendererOptions options;
  options.balancer = "none";
  Renderer renderer(std::move(tracers), options);
  FramePipeline pipeline(renderer);
  constexpr uint64_t kFrames = 6;
  std::vector<uint64_t> prepared;
  uint64_t f = 0;
  std::optional<BandJob> next = job_for(0);
  while (next) {
    const BandJob job = *next;
    next.reset();
    std::optional<FramePipeline::Delivered> done = pipeline.push(job, {}, [&]() -> std::optional<BandJob> {
      if (f + 1 < kFrames) {
        prepared.push_back(f + 1);
        next = job_for(f + 1);
      }
      return next;
    });
    if (done) {
      ASSERT_EQ(done->stats.frame, f - 1);
      for (int y = 0; y < kRows; ++y) ASSERT_EQ(pipeline.image().row(y)[0], static_cast<float>(f - 1));
      // The post of frame f-1: frame f renders meanwhile and has seen f+1's job already.
      if (f + 1 < kFrames) {
        EXPECT_TRUE(saw_next->wait_for(f, std::chrono::milliseconds(5000)))
            << "the band of frame " << f << " did not see frame " << f + 1 << "'s job during the post of frame " << f - 1;
      }
    }
    ++f;
  }
  gates->open(kFrames - 1);  // nothing is announced after the last frame
  ASSERT_TRUE(pipeline.drain().has_value());
  EXPECT_FALSE(gates->gave_up);
  EXPECT_EQ(f, kFrames);
  EXPECT_EQ(prepared, (std::vector<uint64_t>{1, 2, 3, 4, 5}));
  ASSERT_EQ(announced->size(), kFrames - 1);
  for (const auto& [band_frame, job] : *announced) {
    const BandJob expected = job_for(band_frame + 1);
    EXPECT_EQ(job.params.frame_index, band_frame + 1);
    EXPECT_EQ(std::memcmp(&job.camera, &expected.camera, sizeof expected.camera), 0);
  }

  // The contrast: without prepare_next, frame 1's band has not seen frame 2's job when push() returns
  // frame 0, nor while the caller post-processes it; the next push announces it.
  auto gates_serial = std::make_shared<FrameGates>();
  auto saw_serial = std::make_shared<FrameGates>();
  std::vector<std::unique_ptr<Tracer>> serial_tracers;
  serial_tracers.push_back(std::make_unique<AheadWatcher>(gates_serial, saw_serial, announced));
  Renderer serial_renderer(std::move(serial_tracers), options);
  FramePipeline serial(serial_renderer);
  ASSERT_FALSE(serial.push(job_for(0)).has_value());
  ASSERT_TRUE(serial.push(job_for(1)).has_value());
  EXPECT_FALSE(saw_serial->wait_for(1, std::chrono::milliseconds(200)));
  ASSERT_TRUE(serial.push(job_for(2)).has_value());
  EXPECT_TRUE(saw_serial->wait_for(1, std::chrono::milliseconds(5000)));
  gates_serial->open(2);
  ASSERT_TRUE(serial.drain().has_value());
}

namespace {

// Pushes `frames` frames the way `cohort render` does (push with prepare_next); `post(f)` stands for the
// caller's post-processing of delivered frame f. Returns the delivered frames' stats, checked whole and in order.
std::vector<FrameStats> push_with_prepare_next(FramePipeline& pipeline, uint64_t frames,
                                               const std::function<void(uint64_t)>& before_push,
                                               const std::function<void(uint64_t)>& post) {
  std::vector<FrameStats> delivered;
  auto take = [&](std::optional<FramePipeline::Delivered> done) {
    if (!done) return;
    EXPECT_EQ(done->stats.frame, delivered.size()) << "frames in order";
    EXPECT_EQ(done->job.params.frame_index, done->stats.frame);
    for (int y = 0; y < kRows; ++y) EXPECT_EQ(pipeline.image().row(y)[0], static_cast<float>(done->stats.frame)) << "row " << y;
    post(done->stats.frame);
    delivered.push_back(std::move(done->stats));
  };
  std::optional<BandJob> next = job_for(0);
  for (uint64_t f = 0; next; ++f) {
    const BandJob job = *next;
    next.reset();
    before_push(f);
    std::optional<FramePipeline::Delivered> done = pipeline.push(job, {}, [&, f]() -> std::optional<BandJob> {
      if (f + 1 < frames) next = job_for(f + 1);
      return next;
    });
    if (done) {
      EXPECT_EQ(done->stats.frame + 1, f) << "push returns the frame pushed before";
    }
    take(std::move(done));
  }
  take(pipeline.drain());
  EXPECT_FALSE(pipeline.in_flight());
  EXPECT_EQ(delivered.size(), frames);
  return delivered;
}

// With two frames in flight push(N) hands N+1 out as soon as N-1 is merged, before the caller's post of N-1;
// so a band of N that ends during that post finds its next job queued. Here each band of N can end only
// during the post of N-1 (which opens its gate and waits for it to end): with the hand-out after the post
// (COHORT_HAND_OUT_AHEAD=0, the order before) every such band waited for its next job.
void expect_next_job_queued_during_the_post(bool ahead) {
  if (ahead) unsetenv("COHORT_HAND_OUT_AHEAD");
  else setenv("COHORT_HAND_OUT_AHEAD", "0", 1);
  auto gates = std::make_shared<FrameGates>();
  auto ended = std::make_shared<BandsEnded>();
  std::vector<std::unique_ptr<Tracer>> tracers;
  tracers.push_back(std::make_unique<GatedTracer>("gated1", gates, ended));
  tracers.push_back(std::make_unique<GatedTracer>("gated2", gates, ended));
  RendererOptions options;
  options.frames_in_flight = 2;
  Renderer renderer(std::move(tracers), options);
  FramePipeline pipeline(renderer);
  constexpr uint64_t kFrames = 8;
  const std::vector<FrameStats> frames = push_with_prepare_next(
      pipeline, kFrames, [&](uint64_t f) { if (f == 1) gates->open(0); },
      [&](uint64_t f) {
        // The post of frame f: frame f+1's bands end meanwhile, and the post goes on a while after.
        if (f + 1 == kFrames) return;
        gates->open(f + 1);
        EXPECT_TRUE(ended->wait_for(f + 1, 2, std::chrono::milliseconds(5000)));
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      });
  unsetenv("COHORT_HAND_OUT_AHEAD");
  EXPECT_FALSE(gates->gave_up);
  ASSERT_EQ(frames.size(), kFrames);
  for (uint64_t f = 2; f < kFrames; ++f) {
    for (const TracerFrameStats& t : frames[f].tracers) {
      if (ahead) {
        EXPECT_EQ(t.job_wait_ms, 0.0) << "frame " << f << ", " << t.name << ": its job came after its band before had ended";
      } else {
        EXPECT_GE(t.job_wait_ms, 5.0) << "frame " << f << ", " << t.name << ": handed out after the post, it should have waited";
      }
    }
    EXPECT_EQ(spans_of(frames[f], "wait for job", true).empty(), ahead) << "frame " << f;
    const nlohmann::json json = frames[f];  // stats.json has the count per tracer
    for (size_t i = 0; i < frames[f].tracers.size(); ++i)
      EXPECT_EQ(json["tracers"][i]["job_wait_ms"].get<double>(), frames[f].tracers[i].job_wait_ms);
  }
}

}  // namespace

TEST(FramePipeline, WithTwoFramesInFlightTheNextFrameIsQueuedBeforeTheCallersPostOfTheFrameBefore) {
  expect_next_job_queued_during_the_post(true);
}

TEST(FramePipeline, WithTwoFramesInFlightAndTheHandOutAfterThePostTheBandsWaitForTheirJobs) {
  expect_next_job_queued_during_the_post(false);
}

namespace {

// Notes in order each commit applied (its frame number) and each band rendered (its frame index).
class OrderLoggingTracer final : public Tracer {
 public:
  explicit OrderLoggingTracer(std::shared_ptr<std::vector<std::string>> log) : log_(std::move(log)) {}
  std::string name() const override { return "order"; }
  void apply(const cohort::commit::CommitBuffer& commit) override { log_->push_back("apply " + std::to_string(commit.frame())); }
  using Tracer::render_band;
  BandResult render_band(const BandJob& job, BandBuffer& target) override {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    fill_band_with_frame_index(job, target);
    log_->push_back("render " + std::to_string(job.params.frame_index));
    return {};
  }

 private:
  std::shared_ptr<std::vector<std::string>> log_;  // written by its worker only, read once the Renderer is gone
};

}  // namespace

// The next frame handed out ahead keeps every guarantee: each frame's commit (submitted in prepare_next)
// applied once, in order, just before that frame's band; every frame whole and in order while a tracer
// throws on two frames and its rows are re-rendered.
TEST(FramePipeline, WithTwoFramesInFlightTheFramesHandedOutAheadKeepTheirCommitsInOrderThroughFaults) {
  auto log = std::make_shared<std::vector<std::string>>();
  constexpr uint64_t kFrames = 12;
  std::vector<FrameStats> frames;
  {
    std::vector<std::unique_ptr<Tracer>> tracers;
    tracers.push_back(std::make_unique<OrderLoggingTracer>(log));
    SimulatedTracerOptions o;
    o.name = "thrower";
    o.seed = 2;
    o.clock = SimulatedClock::sleep;
    o.throw_on_frames = {4, 5};
    tracers.push_back(std::make_unique<SimulatedTracer>(std::make_shared<SpinSceneCostModel>(3), o));
    RendererOptions options;
    options.frames_in_flight = 2;
    Renderer renderer(std::move(tracers), options);
    auto scene = std::make_shared<cohort::commit::TracerScene>();
    renderer.submit_commit(cohort::commit::CommitBuffer::full(scene, 0));
    FramePipeline pipeline(renderer);
    std::optional<BandJob> next = job_for(0);
    std::map<uint64_t, FrameStats> by_frame;
    for (uint64_t f = 0; next; ++f) {
      const BandJob job = *next;
      next.reset();
      std::optional<FramePipeline::Delivered> done = pipeline.push(job, {}, [&, f]() -> std::optional<BandJob> {
        if (f + 1 >= kFrames) return std::nullopt;
        cohort::commit::CommitBuffer commit;  // frame f+1's commit carries frame number f + 1
        commit.set_frame(f + 1);
        commit.set_camera(job_for(f + 1).camera);
        renderer.submit_commit(commit, [&] { return scene; });
        next = job_for(f + 1);
        return next;
      });
      if (done) {
        for (int y = 0; y < kRows; ++y) ASSERT_EQ(pipeline.image().row(y)[0], static_cast<float>(done->stats.frame));
        frames.push_back(std::move(done->stats));
      }
    }
    if (std::optional<FramePipeline::Delivered> done = pipeline.drain()) frames.push_back(std::move(done->stats));
  }
  ASSERT_EQ(frames.size(), kFrames);
  for (uint64_t f = 0; f < kFrames; ++f) EXPECT_EQ(frames[f].frame, f);
  for (uint64_t f : {4, 5}) EXPECT_EQ(frames[f].tracers[1].outcome, TracerOutcome::threw) << "frame " << f;
  EXPECT_EQ(frames[kFrames - 1].tracers[1].outcome, TracerOutcome::rendered) << "it rejoins";
  // The logging tracer: every commit once, in order (frame f's carries number f, the full scene frame 0's),
  // each after the band of the frame before and before its own frame's band (the first "render f"; a
  // recovery band of frames 4 and 5 comes later, queued behind its band of the next frame).
  std::vector<std::string> applied_in_order, expected_commits;
  for (const std::string& e : *log)
    if (e.rfind("apply ", 0) == 0) applied_in_order.push_back(e);
  for (uint64_t f = 0; f < kFrames; ++f) expected_commits.push_back("apply " + std::to_string(f));
  EXPECT_EQ(applied_in_order, expected_commits);
  for (uint64_t f = 0; f < kFrames; ++f) {
    const auto applied = std::find(log->begin(), log->end(), "apply " + std::to_string(f));
    const auto rendered = std::find(log->begin(), log->end(), "render " + std::to_string(f));
    ASSERT_NE(applied, log->end());
    ASSERT_NE(rendered, log->end());
    EXPECT_LT(applied, rendered) << "frame " << f;
    if (f > 0) {
      EXPECT_LT(std::find(log->begin(), log->end(), "render " + std::to_string(f - 1)), applied)
          << "frame " << f << "'s commit after frame " << f - 1 << "'s band";
    }
  }
}

// A job handed out ahead must be the one pushed next; the pipeline gone with two frames in flight finishes
// both; drain() returns a frame handed out ahead that was never pushed.
TEST(FramePipeline, WithTwoFramesInFlightAFrameHandedOutAheadIsPushedDrainedOrFinished) {
  for (int round = 0; round < 3; ++round) {
    std::vector<std::unique_ptr<Tracer>> tracers;
    tracers.push_back(sleeping_tracer(1));
    RendererOptions options;
    options.frames_in_flight = 2;
    Renderer renderer(std::move(tracers), options);
    {
      FramePipeline pipeline(renderer);
      auto prepare = [](uint64_t f) { return [f]() -> std::optional<BandJob> { return job_for(f); }; };
      EXPECT_FALSE(pipeline.push(job_for(0), {}, prepare(1)).has_value());
      std::optional<FramePipeline::Delivered> zero = pipeline.push(job_for(1), {}, prepare(2));
      ASSERT_TRUE(zero.has_value());
      EXPECT_EQ(zero->stats.frame, 0u);
      EXPECT_EQ(renderer.frames_begun(), 2) << "frame 2 handed out ahead";
      if (round == 0) {
        EXPECT_THROW(pipeline.push(job_for(5)), std::logic_error) << "frame 2 was handed out, not 5";
        std::optional<FramePipeline::Delivered> one = pipeline.push(job_for(2));
        ASSERT_TRUE(one.has_value());
        EXPECT_EQ(one->stats.frame, 1u);
        std::optional<FramePipeline::Delivered> two = pipeline.drain();
        ASSERT_TRUE(two.has_value());
        EXPECT_EQ(two->stats.frame, 2u);
        EXPECT_EQ(pipeline.image().row(0)[0], 2.0f);
      } else if (round == 1) {
        std::optional<FramePipeline::Delivered> one = pipeline.drain();
        ASSERT_TRUE(one.has_value());
        EXPECT_EQ(one->stats.frame, 1u);
        EXPECT_TRUE(pipeline.in_flight());
        std::optional<FramePipeline::Delivered> two = pipeline.drain();
        ASSERT_TRUE(two.has_value());
        EXPECT_EQ(two->stats.frame, 2u);
        EXPECT_EQ(pipeline.image().row(kRows - 1)[0], 2.0f);
        EXPECT_FALSE(pipeline.drain().has_value());
      }
    }
    EXPECT_EQ(renderer.frames_begun(), 0) << "round " << round << ": the pipeline finishes what it handed out";
  }
}
