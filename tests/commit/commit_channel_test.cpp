#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "cohort/commit/array_diff.h"
#include "cohort/commit/commit_channel.h"
#include "cohort/test_support/scene_churn.h"

using namespace cohort::commit;

namespace {

std::shared_ptr<const TracerScene> copy_of(const TracerScene& s) { return std::make_shared<TracerScene>(s); }

}  // namespace

TEST(CommitChannel, FirstCommitIsAFullResync) {
  cohort::test::SceneChurn churn(3);
  CommitChannel channel(1 << 20, copy_of(churn.master()), 0);
  TracerScene tracer;
  ChangeSet changes = apply_commit(channel.begin_frame(), tracer);
  EXPECT_TRUE(changes.full_resync);
  EXPECT_TRUE(same_tracer_scene(tracer, churn.master()));
  EXPECT_EQ(channel.stats().full_resyncs_taken, 1u);
}

TEST(CommitChannel, NothingPublishedGivesAnEmptyCommit) {
  TracerScene master;
  CommitChannel channel(1 << 20, copy_of(master), 5);
  TracerScene tracer;
  apply_commit(channel.begin_frame(), tracer);
  const CommitBuffer& next = channel.begin_frame();
  EXPECT_TRUE(next.empty());
  EXPECT_EQ(next.frame(), 5u);
  EXPECT_FALSE(apply_commit(next, tracer).any());
}

// Tracers that take every frame, every 3rd, every 17th, or only once at the end all end up with the
// master's arrays, and the skipping ones get fewer, coalesced records.
TEST(CommitChannel, TracerThatSkipsFramesConvergesToTheMaster) {
  cohort::test::SceneChurn churn(11);
  const int periods[] = {1, 3, 17, 1000};
  std::vector<std::unique_ptr<CommitChannel>> channels;
  std::vector<TracerScene> tracers(std::size(periods));
  for (size_t t = 0; t < std::size(periods); ++t)
    channels.push_back(std::make_unique<CommitChannel>(size_t(64) << 20, copy_of(churn.master()), 0));
  const uint64_t frames = 200;
  for (uint64_t frame = 1; frame <= frames; ++frame) {
    CommitBuffer records = churn.step(frame);
    for (auto& ch : channels) ch->publish(records, [&] { return copy_of(churn.master()); });
    for (size_t t = 0; t < std::size(periods); ++t)
      if (frame % periods[t] == 0 || frame == frames) apply_commit(channels[t]->begin_frame(), tracers[t]);
  }
  for (size_t t = 0; t < std::size(periods); ++t) {
    std::string where;
    EXPECT_TRUE(same_tracer_scene(tracers[t], churn.master(), &where)) << "period " << periods[t] << ": " << where;
    EXPECT_EQ(tracers[t].version, frames);
    EXPECT_EQ(channels[t]->stats().overflows, 0u);
    EXPECT_EQ(channels[t]->stats().full_resyncs_taken, 1u);
  }
  EXPECT_LT(channels[2]->stats().total_bytes, channels[0]->stats().total_bytes);
  EXPECT_GT(channels[2]->stats().frames_coalesced, 0u);
}

TEST(CommitChannel, OverflowBecomesAFullResyncAndIsCounted) {
  cohort::test::SceneChurn churn(5);
  const size_t budget = 4 * sizeof(KInstance);
  CommitChannel channel(budget, copy_of(churn.master()), 0);
  TracerScene tracer;
  apply_commit(channel.begin_frame(), tracer);
  for (uint64_t frame = 1; frame <= 10; ++frame)
    channel.publish(churn.step(frame, /*heavy=*/true), [&] { return copy_of(churn.master()); });
  const CommitBuffer& commit = channel.begin_frame();
  EXPECT_TRUE(commit.is_full_resync());
  EXPECT_LE(commit.bytes(), budget);
  apply_commit(commit, tracer);
  std::string where;
  EXPECT_TRUE(same_tracer_scene(tracer, churn.master(), &where)) << where;
  CommitStats stats = channel.stats();
  EXPECT_GE(stats.overflows, 1u);
  EXPECT_EQ(stats.full_resyncs_taken, 2u);
  EXPECT_LE(stats.peak_pending_bytes, budget);
}

TEST(CommitChannel, RequestedResyncArrivesWithTheNextPublish) {
  cohort::test::SceneChurn churn(8);
  CommitChannel channel(1 << 20, copy_of(churn.master()), 0);
  TracerScene tracer;
  apply_commit(channel.begin_frame(), tracer);
  tracer.lights.clear();  // the tracer's copy got out of step
  channel.request_resync();
  channel.publish(churn.step(1), [&] { return copy_of(churn.master()); });
  const CommitBuffer& commit = channel.begin_frame();
  EXPECT_TRUE(commit.is_full_resync());
  apply_commit(commit, tracer);
  EXPECT_TRUE(same_tracer_scene(tracer, churn.master()));
}

// The core publishes on one thread while the tracer swaps and applies on another, at its own pace.
// Run under ThreadSanitizer by the `tsan` preset (ctest label `concurrency`).
TEST(CommitChannelConcurrency, ConcurrentPublishAndApplyConverge) {
  cohort::test::SceneChurn churn(21);
  auto initial = copy_of(churn.master());
  CommitChannel channel(256 * 1024, initial, 0);
  const uint64_t frames = 1500;
  std::atomic<bool> done{false};
  TracerScene final_master;

  std::thread core([&] {
    for (uint64_t frame = 1; frame <= frames; ++frame) {
      CommitBuffer records = churn.step(frame, frame % 97 == 0);
      channel.publish(records, [&] { return copy_of(churn.master()); });
      if (frame % 16 == 0) std::this_thread::sleep_for(std::chrono::microseconds(50));
    }
    final_master = churn.master();
    done.store(true, std::memory_order_release);
  });

  TracerScene tracer;
  uint64_t applied = 0;
  std::thread tracer_thread([&] {
    for (;;) {
      bool finished = done.load(std::memory_order_acquire);
      const CommitBuffer& commit = channel.begin_frame();
      apply_commit(commit, tracer);
      ++applied;
      if (finished) break;
      if (applied % 3 == 0) std::this_thread::yield();
    }
  });
  core.join();
  tracer_thread.join();

  std::string where;
  EXPECT_TRUE(same_tracer_scene(tracer, final_master, &where)) << where;
  EXPECT_EQ(tracer.version, frames);
  CommitStats stats = channel.stats();
  EXPECT_EQ(stats.frames_published, frames);
  EXPECT_EQ(stats.commits_taken, applied);
  EXPECT_GT(applied, 2u) << "the tracer never ran alongside the core";
}
