#include <gtest/gtest.h>

#include "cohort/commit/commit_buffer.h"

using namespace cohort::commit;

TEST(CommitBuffer, FullResyncReplacesTheTracerScene) {
  auto master = std::make_shared<TracerScene>();
  master->lights.resize(3);
  master->materials.resize(5);
  TracerScene copy;
  copy.lights.resize(7);
  ChangeSet changes = apply_commit(CommitBuffer::full(master, 42), copy);
  EXPECT_TRUE(changes.full_resync);
  EXPECT_EQ(copy.lights.size(), 3u);
  EXPECT_EQ(copy.materials.size(), 5u);
  EXPECT_EQ(copy.version, 42u);
}
