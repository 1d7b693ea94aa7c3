#include <gtest/gtest.h>

#include <set>

#include <atomic>
#include <future>
#include <thread>

#include <nlohmann/json.hpp>

#include "cohort/core/brief_spin.h"
#include "cohort/core/renderer.h"
#include "cohort/core/simulated_tracer.h"

using namespace cohort::core;

namespace {

constexpr int kWidth = 8, kRows = 96;

std::shared_ptr<SpinSceneCostModel> model() { return std::make_shared<SpinSceneCostModel>(3); }

SimulatedTracerOptions sim(uint64_t tag, double speed = 1.0) {
  SimulatedTracerOptions o;
  o.name = "sim" + std::to_string(tag);
  o.seed = tag;
  o.speed = speed;
  return o;
}

BandJob job_for(uint64_t frame) {
  BandJob job;
  job.camera = spin_camera(kWidth, kRows, 0.05 * static_cast<double>(frame));
  job.params.frame_index = static_cast<kuint>(frame);
  return job;
}

// Every pixel carries (frame, tag of the tracer that wrote it, 1, 1); checks the frame is complete and
// each row came from a tracer whose stats say it rendered those rows.
void expect_complete(const FrameBuffer& fb, uint64_t frame, const FrameStats& stats, const std::vector<uint64_t>& tags) {
  for (int y = 0; y < fb.height; ++y) {
    const float* p = fb.row(y);
    ASSERT_EQ(p[0], static_cast<float>(frame)) << "row " << y << " not rendered for frame " << frame;
    const uint64_t tag = static_cast<uint64_t>(p[1]);
    bool owner = false;
    for (const TracerFrameStats& t : stats.tracers) {
      if (tags[static_cast<size_t>(t.id)] != tag) continue;
      owner = owner || (t.outcome == TracerOutcome::rendered && y >= t.row_begin && y < t.row_end) || t.recovery_rows > 0;
    }
    EXPECT_TRUE(owner) << "row " << y << " written by tag " << tag << " which had no claim on it";
  }
}

// Two simulated tracers, the first twice as fast (tags 1 and 2).
std::vector<std::unique_ptr<Tracer>> unequal_pair() {
  std::vector<std::unique_ptr<Tracer>> tracers;
  tracers.push_back(std::make_unique<SimulatedTracer>(model(), sim(1, 2.0)));
  tracers.push_back(std::make_unique<SimulatedTracer>(model(), sim(2, 1.0)));
  return tracers;
}

RendererOptions perfect_on_reported_time() {
  RendererOptions options;
  options.balancer = "perfect";
  options.use_reported_time = true;
  return options;
}

}  // namespace

TEST(Renderer, DeliversEveryRowAndBalancesUnequalTracers) {
  Renderer renderer(unequal_pair(), perfect_on_reported_time());
  FrameBuffer fb;
  FrameStats stats;
  for (uint64_t f = 0; f < 10; ++f) {
    stats = renderer.render(job_for(f), fb);
    expect_complete(fb, f, stats, {1, 2});
  }
  EXPECT_EQ(stats.dropped, 0);
  EXPECT_GT(stats.tracers[0].row_end - stats.tracers[0].row_begin, stats.tracers[1].row_end - stats.tracers[1].row_begin);
  EXPECT_LT(stats.idle_percent, 15.0);
  const nlohmann::json j = stats;
  EXPECT_EQ(j["tracers"].size(), 2u);
  EXPECT_EQ(j["tracers"][0]["outcome"], "rendered");
  EXPECT_DOUBLE_EQ(j["idle_percent"].get<double>(), stats.idle_percent);
}

// The hand-over spin (RendererOptions::handoff_spin) changes when threads wake, nothing else: without it,
// and with one longer than a whole frame (every wait ends while polling), the same bands and complete frames.
TEST(Renderer, TheHandOffSpinChangesOnlyWhenThreadsWake) {
  auto run = [](std::chrono::microseconds spin) {
    RendererOptions options = perfect_on_reported_time();
    options.handoff_spin = spin;
    Renderer renderer(unequal_pair(), options);
    FrameBuffer fb;
    std::vector<std::pair<int, int>> bands;
    for (uint64_t f = 0; f < 12; ++f) {
      const FrameStats stats = renderer.render(job_for(f), fb);
      expect_complete(fb, f, stats, {1, 2});
      EXPECT_EQ(stats.dropped, 0);
      for (const TracerFrameStats& t : stats.tracers) bands.emplace_back(t.row_begin, t.row_end);
    }
    return bands;
  };
  EXPECT_EQ(run(std::chrono::microseconds(0)), run(std::chrono::microseconds(20000)));
}

TEST(BriefSpin, HoldsAsSoonAsReadyAndGivesUpAtItsDeadline) {
  using Clock = std::chrono::steady_clock;
  EXPECT_TRUE(spin_until(Clock::now() - std::chrono::seconds(1), [] { return true; }));
  const auto start = Clock::now();
  EXPECT_FALSE(spin_until(start + std::chrono::milliseconds(2), [] { return false; }));
  EXPECT_GE(Clock::now() - start, std::chrono::milliseconds(2));
  std::atomic<bool> flag{false};
  std::thread setter([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    flag.store(true);
  });
  EXPECT_TRUE(spin_until(Clock::now() + std::chrono::seconds(10), [&] { return flag.load(); }));
  setter.join();
}

TEST(Renderer, ATracerThatThrowsIsDroppedItsRowsReRenderedAndItRejoins) {
  std::vector<std::unique_ptr<Tracer>> tracers;
  auto faulty = sim(2);
  faulty.throw_on_frames = {3};
  tracers.push_back(std::make_unique<SimulatedTracer>(model(), sim(1)));
  tracers.push_back(std::make_unique<SimulatedTracer>(model(), faulty));
  tracers.push_back(std::make_unique<SimulatedTracer>(model(), sim(3)));
  RendererOptions options;
  options.use_reported_time = true;
  Renderer renderer(std::move(tracers), options);
  FrameBuffer fb;
  for (uint64_t f = 0; f < 6; ++f) {
    const FrameStats stats = renderer.render(job_for(f), fb);
    expect_complete(fb, f, stats, {1, 2, 3});
    if (f == 3) {
      EXPECT_EQ(stats.dropped, 1);
      EXPECT_EQ(stats.tracers[1].outcome, TracerOutcome::threw);
      EXPECT_NE(stats.tracers[1].error.find("simulated device fault"), std::string::npos);
      EXPECT_EQ(stats.tracers[0].recovery_rows + stats.tracers[2].recovery_rows,
                stats.tracers[1].row_end - stats.tracers[1].row_begin);
    } else {
      EXPECT_EQ(stats.dropped, 0) << "frame " << f;
      EXPECT_EQ(stats.tracers[1].outcome, TracerOutcome::rendered) << "frame " << f;
    }
  }
}

TEST(Renderer, ATracerThatTimesOutIsDroppedAndRejoinsAfterFinishingLateWork) {
  std::vector<std::unique_ptr<Tracer>> tracers;
  auto slow = sim(2);
  slow.hang_on_frames = {1};
  slow.hang_ms = 600.0;
  tracers.push_back(std::make_unique<SimulatedTracer>(model(), sim(1)));
  tracers.push_back(std::make_unique<SimulatedTracer>(model(), slow));
  RendererOptions options;
  options.use_reported_time = true;
  options.frame_timeout = std::chrono::milliseconds(150);  // generous: a loaded CI machine must not drop the healthy one
  Renderer renderer(std::move(tracers), options);
  FrameBuffer fb;
  bool rejoined = false, was_busy = false;
  for (uint64_t f = 0; f < 400 && !rejoined; ++f) {
    const FrameStats stats = renderer.render(job_for(f), fb);
    expect_complete(fb, f, stats, {1, 2});
    if (f == 1) {
      EXPECT_EQ(stats.tracers[1].outcome, TracerOutcome::timed_out);
      EXPECT_EQ(stats.dropped, 1);
      EXPECT_EQ(stats.tracers[0].recovery_rows, stats.tracers[1].row_end - stats.tracers[1].row_begin);
    } else if (f > 1) {
      if (stats.tracers[1].outcome == TracerOutcome::busy) {
        was_busy = true;
        EXPECT_EQ(stats.tracers[0].row_begin, 0);
        EXPECT_EQ(stats.tracers[0].row_end, kRows);  // the other tracer renders everything meanwhile
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      } else {
        EXPECT_EQ(stats.tracers[1].outcome, TracerOutcome::rendered);
        rejoined = true;
      }
    }
  }
  EXPECT_TRUE(was_busy);
  EXPECT_TRUE(rejoined);
}

TEST(Renderer, WhenEveryTracerFailsTheFrameThrowsWithTheReason) {
  std::vector<std::unique_ptr<Tracer>> tracers;
  auto faulty = sim(1);
  faulty.throw_on_frames = {0};
  tracers.push_back(std::make_unique<SimulatedTracer>(model(), faulty));
  Renderer renderer(std::move(tracers), RendererOptions{});
  FrameBuffer fb;
  try {
    renderer.render(job_for(0), fb);
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("could not be rendered"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(renderer.render(job_for(1), fb));  // it rejoins on the next frame
}

TEST(Renderer, CommitsSubmittedBetweenFramesCoalesceIntoOne) {
  auto m = model();
  auto a = std::make_unique<SimulatedTracer>(m, sim(1));
  SimulatedTracer* a_view = a.get();
  std::vector<std::unique_ptr<Tracer>> tracers;
  tracers.push_back(std::move(a));
  RendererOptions options;
  options.use_reported_time = true;
  Renderer renderer(std::move(tracers), options);
  auto scene = std::make_shared<cohort::commit::TracerScene>();
  renderer.submit_commit(cohort::commit::CommitBuffer::full(scene, 1));
  renderer.submit_commit(cohort::commit::CommitBuffer::full(scene, 2));
  FrameBuffer fb;
  renderer.render(job_for(0), fb);
  EXPECT_EQ(a_view->commits_applied(), 1u);  // frames 1 and 2 arrive as one commit
  EXPECT_EQ(a_view->last_commit_frame(), 2u);
  EXPECT_EQ(renderer.commit_stats(0).frames_coalesced, 1u);
  renderer.render(job_for(1), fb);
  EXPECT_EQ(a_view->commits_applied(), 1u);  // nothing new: nothing applied
}

TEST(Renderer, RejectsNoTracersAndUnknownBalancers) {
  EXPECT_THROW(Renderer({}, RendererOptions{}), std::invalid_argument);
  std::vector<std::unique_ptr<Tracer>> tracers;
  tracers.push_back(std::make_unique<SimulatedTracer>(model(), sim(1)));
  RendererOptions options;
  options.balancer = "magic";
  EXPECT_THROW(Renderer(std::move(tracers), options), std::invalid_argument);
}

TEST(Renderer, CommitsSubmittedDuringAFrameWaitForTheNextOne) {
  auto a = std::make_unique<SimulatedTracer>(model(), sim(1));
  SimulatedTracer* view = a.get();
  std::vector<std::unique_ptr<Tracer>> tracers;
  tracers.push_back(std::move(a));
  RendererOptions options;
  options.use_reported_time = true;
  Renderer renderer(std::move(tracers), options);
  auto scene = std::make_shared<cohort::commit::TracerScene>();
  FrameBuffer fb;
  renderer.submit_commit(cohort::commit::CommitBuffer::full(scene, 1));
  renderer.begin_frame(job_for(0), fb);
  renderer.submit_commit(cohort::commit::CommitBuffer::full(scene, 2));  // the core prepares frame 1
  EXPECT_THROW(renderer.begin_frame(job_for(1), fb), std::logic_error);
  renderer.finish_frame();
  EXPECT_EQ(view->last_commit_frame(), 1u);
  EXPECT_EQ(view->commits_applied(), 1u);
  renderer.render(job_for(1), fb);
  EXPECT_EQ(view->last_commit_frame(), 2u);
  EXPECT_THROW(renderer.finish_frame(), std::logic_error);
}

TEST(Renderer, PerRowWorkCountsReachTheBalancer) {
  // Row Cost with the tracers' per-row work counts balances a static view in one step; without
  // them it has to learn the row costs from band times over several frames.
  auto idle_after_one_measured_frame = [](bool use_row_work) {
    std::vector<std::unique_ptr<Tracer>> tracers;
    for (uint64_t tag : {1u, 2u, 3u}) {
      auto o = sim(tag);
      o.report_row_work = true;
      o.row_work_error = 0.0;
      tracers.push_back(std::make_unique<SimulatedTracer>(model(), o));
    }
    RendererOptions options;
    options.balancer = "row-cost";
    options.use_reported_time = true;
    options.use_row_work = use_row_work;
    Renderer renderer(std::move(tracers), options);
    FrameBuffer fb;
    BandJob job = job_for(0);
    job.camera = spin_camera(kWidth, 480, 0.7);
    FrameStats stats;
    for (int f = 0; f < 2; ++f) stats = renderer.render(job, fb);
    return stats.idle_percent;
  };
  const double with_counts = idle_after_one_measured_frame(true), without = idle_after_one_measured_frame(false);
  EXPECT_LT(with_counts, 4.0);  // what is left is rounding to 4-row units
  EXPECT_LT(2.0 * with_counts, without);
}

namespace {

// A frame's records that a tracer can apply: a camera change.
cohort::commit::CommitBuffer camera_records(uint64_t frame) {
  cohort::commit::CommitBuffer c;
  c.set_frame(frame);
  c.set_camera(spin_camera(kWidth, kRows, 0.01 * static_cast<double>(frame)));
  return c;
}

}  // namespace

TEST(Renderer, ATracerWhoseCommitThrowsSitsOutUntilItsFullResync) {
  auto m = model();
  SimulatedTracerOptions failing = sim(2);
  failing.throw_on_commits = {3};
  auto b = std::make_unique<SimulatedTracer>(m, failing);
  SimulatedTracer* b_view = b.get();
  std::vector<std::unique_ptr<Tracer>> tracers;
  tracers.push_back(std::make_unique<SimulatedTracer>(m, sim(1)));
  tracers.push_back(std::move(b));
  RendererOptions options;
  options.use_reported_time = true;
  Renderer renderer(std::move(tracers), options);
  auto master = std::make_shared<cohort::commit::TracerScene>();
  renderer.submit_commit(cohort::commit::CommitBuffer::full(master, 0));
  FrameBuffer fb;
  for (uint64_t f = 1; f <= 6; ++f) {
    renderer.submit_commit(camera_records(f), [&] { return master; });
    const FrameStats stats = renderer.render(job_for(f), fb);
    expect_complete(fb, f, stats, {1, 2});
    const TracerFrameStats& t = stats.tracers[1];
    if (f == 3) {
      EXPECT_EQ(t.outcome, TracerOutcome::threw) << "frame " << f;
      EXPECT_NE(t.error.find("does not fit"), std::string::npos) << t.error;
    } else {
      EXPECT_EQ(t.outcome, TracerOutcome::rendered) << "frame " << f;
    }
  }
  EXPECT_EQ(b_view->full_resyncs_applied(), 2u);  // the initial one and the one after the failure
  EXPECT_EQ(renderer.commit_stats(1).resyncs_requested, 1u);
  EXPECT_EQ(b_view->last_commit_frame(), 6u);
}

TEST(Renderer, PendingCommitsOverTheBudgetBecomeAFullResync) {
  auto a = std::make_unique<SimulatedTracer>(model(), sim(1));
  SimulatedTracer* view = a.get();
  std::vector<std::unique_ptr<Tracer>> tracers;
  tracers.push_back(std::move(a));
  RendererOptions options;
  options.use_reported_time = true;
  options.commit_budget_bytes = 200;  // one light record is about 200 bytes
  Renderer renderer(std::move(tracers), options);
  auto master = std::make_shared<cohort::commit::TracerScene>();
  renderer.submit_commit(cohort::commit::CommitBuffer::full(master, 0));
  FrameBuffer fb;
  renderer.render(job_for(0), fb);
  for (uint64_t f = 1; f <= 3; ++f) {  // camera records coalesce, so use lights: each adds bytes
    cohort::commit::CommitBuffer c;
    c.set_frame(f);
    c.set_light_count(static_cast<uint32_t>(f));
    for (uint32_t i = 0; i < f; ++i) c.set_light(i, KLight{});
    renderer.submit_commit(c, [&] { return master; });
  }
  renderer.render(job_for(1), fb);
  EXPECT_GE(renderer.commit_stats(0).overflows, 1u);
  EXPECT_EQ(view->full_resyncs_applied(), 2u);
  EXPECT_EQ(view->last_commit_frame(), 3u);
}

TEST(Renderer, AResyncWithoutASnapshotOfIncrementalRecordsIsAnError) {
  std::vector<std::unique_ptr<Tracer>> tracers;
  tracers.push_back(std::make_unique<SimulatedTracer>(model(), sim(1)));
  RendererOptions options;
  options.commit_budget_bytes = 100;
  Renderer renderer(std::move(tracers), options);
  renderer.submit_commit(cohort::commit::CommitBuffer::full(std::make_shared<cohort::commit::TracerScene>(), 0));
  cohort::commit::CommitBuffer big;
  big.set_frame(1);
  big.set_light_count(4);
  for (uint32_t i = 0; i < 4; ++i) big.set_light(i, KLight{});
  EXPECT_THROW(renderer.submit_commit(big), std::logic_error);
}

namespace {

// A tracer stuck in render_band until the test lets it go (a device that never comes back), which
// says when it is destroyed.
class StuckTracer final : public Tracer {
 public:
  StuckTracer(std::shared_future<void> release, std::shared_ptr<std::atomic<bool>> destroyed)
      : release_(std::move(release)), destroyed_(std::move(destroyed)) {}
  ~StuckTracer() override { *destroyed_ = true; }
  std::string name() const override { return "stuck"; }
  void apply(const cohort::commit::CommitBuffer&) override {}
  using Tracer::render_band;
  BandResult render_band(const BandJob&, BandBuffer&) override {
    release_.wait();
    return {};
  }

 private:
  std::shared_future<void> release_;
  std::shared_ptr<std::atomic<bool>> destroyed_;
};

}  // namespace

TEST(Renderer, ATracerThatNeverReturnsDoesNotBlockShutdownAndIsFreedIfItReturns) {
  std::promise<void> release;
  auto destroyed = std::make_shared<std::atomic<bool>>(false);
  {
    std::vector<std::unique_ptr<Tracer>> tracers;
    tracers.push_back(std::make_unique<SimulatedTracer>(model(), sim(1)));
    tracers.push_back(std::make_unique<StuckTracer>(release.get_future().share(), destroyed));
    RendererOptions options;
    options.use_reported_time = true;
    options.frame_timeout = std::chrono::milliseconds(20);
    options.shutdown_timeout = std::chrono::milliseconds(20);
    Renderer renderer(std::move(tracers), options);
    FrameBuffer fb;
    const FrameStats stats = renderer.render(job_for(0), fb);
    expect_complete(fb, 0, stats, {1, 99});
    EXPECT_EQ(stats.tracers[1].outcome, TracerOutcome::timed_out);
  }  // the destructor returns although the stuck tracer is still inside render_band
  EXPECT_FALSE(*destroyed) << "the stuck tracer must stay alive while its call runs";
  release.set_value();
  for (int i = 0; i < 500 && !*destroyed; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  EXPECT_TRUE(*destroyed) << "once it returns, its abandoned worker frees it";
}

TEST(SimulatedTracer, AFixedCostIsPaidPerBandWhateverItsSizeAndNotScaledBySpeed) {
  auto shared_model = model();
  SimulatedTracerOptions plain = sim(1, 0.5), fixed = sim(1, 0.5);
  fixed.fixed_ms = 2.0;
  SimulatedTracer without(shared_model, plain), with(shared_model, fixed);
  FrameBuffer target;
  target.resize(kWidth, kRows);
  for (auto [begin, end] : {std::pair{0, 1}, std::pair{10, 60}}) {
    BandJob job = job_for(3);
    job.params.row_begin = static_cast<kuint>(begin);
    job.params.row_end = static_cast<kuint>(end);
    const double base = without.render_band(job, target).device_ms;
    EXPECT_GT(base, 0.0);
    EXPECT_NEAR(with.render_band(job, target).device_ms, base + 2.0, 1e-9) << "rows [" << begin << ", " << end << ")";
  }
  BandJob empty = job_for(3);
  empty.params.row_begin = empty.params.row_end = 5;
  EXPECT_EQ(with.render_band(empty, target).device_ms, 0.0) << "no band, no launch";
  fixed.fixed_ms = -1.0;
  EXPECT_THROW(SimulatedTracer(shared_model, fixed), std::invalid_argument);
}

namespace {

// A simulated tracer that also publishes the last commit frame it applied, readable from any thread
// (a benched tracer applies its commits on its own thread while the core goes on).
class CommitWatchingTracer final : public Tracer {
 public:
  CommitWatchingTracer(std::unique_ptr<SimulatedTracer> inner, std::shared_ptr<std::atomic<uint64_t>> last)
      : inner_(std::move(inner)), last_(std::move(last)) {}
  std::string name() const override { return inner_->name(); }
  void apply(const cohort::commit::CommitBuffer& commit) override {
    inner_->apply(commit);
    last_->store(commit.frame());
  }
  using Tracer::render_band;
  BandResult render_band(const BandJob& job, BandBuffer& target) override { return inner_->render_band(job, target); }

 private:
  std::unique_ptr<SimulatedTracer> inner_;
  std::shared_ptr<std::atomic<uint64_t>> last_;
};

// Fast tracer 1 and tracer 2, 50x slower with a 2 ms fixed cost per band: on 96 rows (about 6 ms
// for the fast one alone) the slow one can only slow the frame down.
std::vector<std::unique_ptr<Tracer>> fast_and_hopeless(std::shared_ptr<std::atomic<uint64_t>> slow_commit,
                                                      SimulatedTracerOptions fast = sim(1, 1.0)) {
  SimulatedTracerOptions slow = sim(2, 0.02);
  slow.fixed_ms = 2.0;
  std::vector<std::unique_ptr<Tracer>> tracers;
  tracers.push_back(std::make_unique<SimulatedTracer>(model(), fast));
  tracers.push_back(std::make_unique<CommitWatchingTracer>(std::make_unique<SimulatedTracer>(model(), slow), std::move(slow_commit)));
  return tracers;
}

RendererOptions whole_cost_options() {
  RendererOptions options;
  options.balancer = "whole-cost";
  options.balancer_options.probe_interval = 5;
  options.use_reported_time = true;
  return options;
}

}  // namespace

TEST(Renderer, ABenchedTracerKeepsApplyingCommitsAndIsProbedOnTheSide) {
  auto slow_commit = std::make_shared<std::atomic<uint64_t>>(0);
  Renderer renderer(fast_and_hopeless(slow_commit), whole_cost_options());
  auto scene = std::make_shared<cohort::commit::TracerScene>();
  FrameBuffer fb;
  int benched = 0, probes = 0;
  for (uint64_t f = 0; f < 40; ++f) {
    renderer.submit_commit(cohort::commit::CommitBuffer::full(scene, f + 1));
    const FrameStats stats = renderer.render(job_for(f), fb);
    expect_complete(fb, f, stats, {1, 2});
    EXPECT_EQ(stats.dropped, 0);
    const TracerFrameStats& slow = stats.tracers[1];
    if (f >= 10) {
      EXPECT_NE(slow.outcome, TracerOutcome::rendered) << "frame " << f;
      EXPECT_EQ(stats.tracers[0].row_end - stats.tracers[0].row_begin, kRows) << "frame " << f;
      EXPECT_EQ(stats.idle_percent, 0.0) << "a benched tracer is not waited for, so not idle";
    }
    benched += slow.outcome == TracerOutcome::no_rows;
    probes += slow.probe_rows > 0;
    // Frames on the virtual clock take no time: let its side job (this frame's commit) land first,
    // else it is still busy at the next frame and sits it out.
    for (int i = 0; i < 2000 && slow.outcome == TracerOutcome::no_rows && slow_commit->load() != f + 1; ++i)
      std::this_thread::sleep_for(std::chrono::microseconds(100));
  }
  // Benched, or still on its last side job when a frame began (it then sits the frame out).
  EXPECT_GE(benched, 10);
  EXPECT_GE(probes, 3);
  // The last commit reaches it with the next side job it is ready for; wait for that event.
  for (uint64_t f = 40; f < 400 && slow_commit->load() != 40; ++f) {
    renderer.render(job_for(f), fb);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  EXPECT_EQ(slow_commit->load(), 40u);
}

TEST(Renderer, ABenchedTracerTakesItsCommitsCoalescedEveryNFrames) {
  auto slow_commit = std::make_shared<std::atomic<uint64_t>>(0);
  RendererOptions options = whole_cost_options();
  options.balancer_options.probe_interval = 100000;  // no probes: only the commit side jobs
  options.benched_commit_every = 6;
  Renderer renderer(fast_and_hopeless(slow_commit), options);
  auto scene = std::make_shared<cohort::commit::TracerScene>();
  FrameBuffer fb;
  uint64_t behind = 0, taken_before = 0;
  for (uint64_t f = 0; f < 60; ++f) {
    renderer.submit_commit(cohort::commit::CommitBuffer::full(scene, f + 1));
    const FrameStats stats = renderer.render(job_for(f), fb);
    expect_complete(fb, f, stats, {1, 2});
    if (f >= 10) { EXPECT_EQ(stats.tracers[1].row_end - stats.tracers[1].row_begin, 0) << "frame " << f; }
    // A commit handed out this frame (the channel counts it at once) lands on the tracer's own thread:
    // wait for it (bounded), so that the next frame finds the tracer idle and the lag is the Renderer's
    // doing, not the machine's load.
    const uint64_t taken = renderer.commit_stats(1).commits_taken;
    if (taken != taken_before)
      for (int i = 0; i < 2000 && slow_commit->load() != f + 1; ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    taken_before = taken;
    if (f >= 10) behind = std::max<uint64_t>(behind, f + 1 - slow_commit->load());
  }
  // Benched from about frame 5: a side job every 6th frame, carrying the commits since the last.
  const cohort::commit::CommitStats c = renderer.commit_stats(1);
  EXPECT_LE(c.commits_taken, 20u) << "it took a commit nearly every frame";
  EXPECT_GE(c.frames_coalesced, 35u);
  EXPECT_EQ(c.overflows, 0u);
  EXPECT_LE(behind, 6u) << "never more than 6 frames behind";
}

TEST(Renderer, ABenchedTracerReRendersTheRowsOfATracerThatFailed) {
  SimulatedTracerOptions fast = sim(1, 1.0);
  fast.throw_on_frames = {20};
  Renderer renderer(fast_and_hopeless(std::make_shared<std::atomic<uint64_t>>(0), fast), whole_cost_options());
  FrameBuffer fb;
  for (uint64_t f = 0; f < 24; ++f) {
    const FrameStats stats = renderer.render(job_for(f), fb);
    expect_complete(fb, f, stats, {1, 2});
    if (f == 20) {
      EXPECT_EQ(stats.dropped, 1);
      EXPECT_EQ(stats.tracers[0].outcome, TracerOutcome::threw);
      EXPECT_EQ(stats.tracers[1].recovery_rows, kRows) << "the benched tracer was the only one left";
    }
  }
}

namespace {

// Renders at once and says its band cost `ms_per_row` a row (BandResult::balance_ms), as a tracer that
// began its band ahead of its job does: its wall time says nothing of its speed.
class HeadStartTracer final : public Tracer {
 public:
  explicit HeadStartTracer(double ms_per_row) : ms_per_row_(ms_per_row) {}
  std::string name() const override { return "head-start"; }
  void apply(const cohort::commit::CommitBuffer&) override {}
  using Tracer::render_band;
  BandResult render_band(const BandJob& job, BandBuffer& target) override {
    std::vector<float> row(static_cast<size_t>(target.width()) * 4, static_cast<float>(job.params.frame_index));
    for (kuint y = job.params.row_begin; y < job.params.row_end; ++y)
      target.store(static_cast<int>(y), 0, row.data(), static_cast<size_t>(target.width()));
    BandResult result;
    result.balance_ms = ms_per_row_ * static_cast<double>(job.params.row_end - job.params.row_begin);
    return result;
  }

 private:
  double ms_per_row_;
};

}  // namespace

TEST(Renderer, TheBalancerChargesATracerTheCostItReportsForABandBegunAhead) {
  std::vector<std::unique_ptr<Tracer>> tracers;
  tracers.push_back(std::make_unique<HeadStartTracer>(1.0));
  tracers.push_back(std::make_unique<HeadStartTracer>(3.0));
  RendererOptions options;
  options.balancer = "perfect";
  Renderer renderer(std::move(tracers), options);
  FrameBuffer fb;
  FrameStats stats;
  for (uint64_t f = 0; f < 6; ++f) stats = renderer.render(job_for(f), fb);
  // A third of the speed, a third of the rows: 72 and 24 of 96 (the balancer's 4-row units).
  EXPECT_EQ(stats.tracers[0].row_end - stats.tracers[0].row_begin, 72);
  EXPECT_EQ(stats.tracers[1].row_end - stats.tracers[1].row_begin, 24);
  EXPECT_NEAR(stats.tracers[0].ms, 72.0, 1.0) << "the cost it reported (and its commit's apply), not its wall time";
}

namespace {

// A simulated tracer that can say it is away (Tracer::available), counts its bands and publishes the
// last commit frame it applied, readable from any thread.
class AwayTracer final : public Tracer {
 public:
  explicit AwayTracer(std::unique_ptr<SimulatedTracer> inner) : inner_(std::move(inner)) {}
  std::string name() const override { return inner_->name(); }
  bool available() const override { return !away->load(); }
  void while_away() override { checks->fetch_add(1); }
  bool checks_in_every_frame() const override { return every_frame->load(); }
  void apply(const cohort::commit::CommitBuffer& commit) override {
    inner_->apply(commit);
    last_commit->store(commit.frame());
  }
  using Tracer::render_band;
  BandResult render_band(const BandJob& job, BandBuffer& target) override {
    bands->fetch_add(1);
    return inner_->render_band(job, target);
  }
  std::shared_ptr<std::atomic<bool>> away = std::make_shared<std::atomic<bool>>(false);
  std::shared_ptr<std::atomic<uint64_t>> last_commit = std::make_shared<std::atomic<uint64_t>>(0);
  std::shared_ptr<std::atomic<int>> bands = std::make_shared<std::atomic<int>>(0);
  std::shared_ptr<std::atomic<int>> checks = std::make_shared<std::atomic<int>>(0);
  std::shared_ptr<std::atomic<bool>> every_frame = std::make_shared<std::atomic<bool>>(false);

 private:
  std::unique_ptr<SimulatedTracer> inner_;
};

}  // namespace

// An away tracer gets its commits on the side every benched_commit_every frames (coalesced meanwhile),
// unless it waits for an answer (Tracer::checks_in_every_frame: a remote node warming up): then every frame,
// so that it is back the frame after the answer comes.
TEST(Renderer, AnAwayTracerThatChecksInEveryFrameGetsItsSideJobEveryFrame) {
  auto away_tracer = std::make_unique<AwayTracer>(std::make_unique<SimulatedTracer>(model(), sim(2)));
  const auto away = away_tracer->away;
  const auto last_commit = away_tracer->last_commit;
  const auto checks = away_tracer->checks;
  const auto every_frame = away_tracer->every_frame;
  std::vector<std::unique_ptr<Tracer>> tracers;
  tracers.push_back(std::make_unique<SimulatedTracer>(model(), sim(1)));
  tracers.push_back(std::move(away_tracer));
  RendererOptions options;
  options.use_reported_time = true;
  options.benched_commit_every = 4;
  Renderer renderer(std::move(tracers), options);
  auto scene = std::make_shared<cohort::commit::TracerScene>();
  FrameBuffer fb;
  constexpr uint64_t kAwayFrom = 1, kEveryFrameFrom = 9, kFrames = 17;
  int checks_coalesced = 0, checks_every_frame = 0;
  for (uint64_t f = 0; f < kFrames; ++f) {
    away->store(f >= kAwayFrom);
    every_frame->store(f >= kEveryFrameFrom);
    const int checks_before = checks->load();
    renderer.submit_commit(cohort::commit::CommitBuffer::full(scene, f + 1));
    const FrameStats stats = renderer.render(job_for(f), fb);
    expect_complete(fb, f, stats, {1, 2});
    if (f < kAwayFrom) continue;
    EXPECT_EQ(stats.tracers[1].outcome, TracerOutcome::away) << "frame " << f;
    // A side job handed out this frame brings this frame's commit: let it land (bounded), so that the
    // tracer is not still busy with it when the next frame begins.
    for (int i = 0; i < 500 && last_commit->load() != f + 1; ++i) std::this_thread::sleep_for(std::chrono::microseconds(100));
    (f < kEveryFrameFrom ? checks_coalesced : checks_every_frame) += checks->load() - checks_before;
  }
  EXPECT_EQ(checks_coalesced, int(kEveryFrameFrom - kAwayFrom) / 4) << "every 4th frame while it waits for nothing";
  EXPECT_EQ(checks_every_frame, int(kFrames - kEveryFrameFrom)) << "every frame while it checks in every frame";
  EXPECT_EQ(last_commit->load(), kFrames) << "its commits keep coming";
}

TEST(Renderer, AnAwayTracerGetsNoRowsIsNotWaitedForKeepsItsCommitsAndIsBackWhenAvailable) {
  auto away_tracer = std::make_unique<AwayTracer>(std::make_unique<SimulatedTracer>(model(), sim(2)));
  const auto away = away_tracer->away;
  const auto last_commit = away_tracer->last_commit;
  const auto bands = away_tracer->bands;
  const auto checks = away_tracer->checks;
  std::vector<std::unique_ptr<Tracer>> tracers;
  tracers.push_back(std::make_unique<SimulatedTracer>(model(), sim(1)));
  tracers.push_back(std::move(away_tracer));
  tracers.push_back(std::make_unique<SimulatedTracer>(model(), sim(3)));
  RendererOptions options;
  options.use_reported_time = true;
  Renderer renderer(std::move(tracers), options);
  auto scene = std::make_shared<cohort::commit::TracerScene>();
  FrameBuffer fb;
  constexpr uint64_t kAwayFrom = 3, kBackAt = 9;
  for (uint64_t f = 0; f < 14; ++f) {
    away->store(f >= kAwayFrom && f < kBackAt);
    const int bands_before = bands->load();
    renderer.submit_commit(cohort::commit::CommitBuffer::full(scene, f + 1));
    const FrameStats stats = renderer.render(job_for(f), fb);
    expect_complete(fb, f, stats, {1, 2, 3});
    EXPECT_EQ(stats.dropped, 0) << "frame " << f << ": nothing failed, nothing was re-rendered";
    const TracerFrameStats& t = stats.tracers[1];
    if (f >= kAwayFrom && f < kBackAt) {
      EXPECT_EQ(t.outcome, TracerOutcome::away) << "frame " << f;
      EXPECT_EQ(t.row_end - t.row_begin, 0) << "frame " << f;
      EXPECT_EQ(bands->load(), bands_before) << "frame " << f << ": an away tracer was asked for a band";
      EXPECT_EQ(stats.tracers[0].recovery_rows + stats.tracers[2].recovery_rows, 0) << "frame " << f;
      EXPECT_EQ((stats.tracers[0].row_end - stats.tracers[0].row_begin) +
                    (stats.tracers[2].row_end - stats.tracers[2].row_begin), kRows)
          << "frame " << f << ": the others share the whole frame";
      EXPECT_EQ(nlohmann::json(stats)["tracers"][1]["outcome"], "away");
      // Its commits come on the side, unwaited: let this one land (bounded) before the next frame, so
      // that it is not still busy with it then.
      for (int i = 0; i < 2000 && last_commit->load() != f + 1; ++i)
        std::this_thread::sleep_for(std::chrono::microseconds(100));
      EXPECT_EQ(last_commit->load(), f + 1) << "frame " << f << ": an away tracer keeps getting its commits";
      EXPECT_EQ(checks->load(), static_cast<int>(f + 1 - kAwayFrom)) << "frame " << f << ": Tracer::while_away with each";
    } else {
      EXPECT_EQ(t.outcome, TracerOutcome::rendered) << "frame " << f;
      EXPECT_GT(t.row_end - t.row_begin, 0) << "frame " << f;
      EXPECT_EQ(bands->load(), bands_before + 1) << "frame " << f;
    }
  }
  EXPECT_EQ(checks->load(), static_cast<int>(kBackAt - kAwayFrom)) << "while_away only while away";
}
