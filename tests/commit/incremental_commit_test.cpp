#include <gtest/gtest.h>

#include "cohort/commit/array_diff.h"
#include "cohort/commit/commit_buffer.h"
#include "cohort/test_support/scene_churn.h"

using namespace cohort::commit;

namespace {

KInstance instance_at(float x) {
  KInstance inst{};
  inst.object_to_world[3] = x;
  inst.mask = K_MASK_PRIMARY;
  return inst;
}

}  // namespace

TEST(CommitBuffer, SameElementWrittenTwiceKeepsTheLastValueAndCountsOnce) {
  CommitBuffer c;
  c.set_instance(3, instance_at(1.0f));
  size_t after_first = c.bytes();
  c.set_instance(3, instance_at(2.0f));
  EXPECT_EQ(c.bytes(), after_first);
  EXPECT_EQ(c.record_count(), 1u);
  EXPECT_EQ(c.instances().at(3).object_to_world[3], 2.0f);
  EXPECT_EQ(after_first, kRecordHeaderBytes + sizeof(KInstance));
}

TEST(CommitBuffer, ShrinkingDropsEarlierWritesPastTheNewEnd) {
  CommitBuffer c;
  c.set_instance_count(10);
  for (uint32_t i = 0; i < 10; ++i) c.set_instance(i, instance_at(float(i)));
  c.set_instance_count(4);
  EXPECT_EQ(c.instances().size(), 4u);
  EXPECT_EQ(c.bytes(), kRecordHeaderBytes + 4 * (kRecordHeaderBytes + sizeof(KInstance)));
}

TEST(CommitBuffer, IncrementalCommitUpdatesOnlyWhatItNames) {
  TracerScene scene;
  scene.instances = {instance_at(0), instance_at(1), instance_at(2)};
  scene.lights.resize(2);
  CommitBuffer c;
  c.set_frame(7);
  c.set_instance(1, instance_at(42.0f));
  ChangeSet changes = apply_commit(c, scene);
  EXPECT_FALSE(changes.full_resync);
  EXPECT_TRUE(changes.instances);
  EXPECT_FALSE(changes.lights);
  EXPECT_FALSE(changes.geometry);
  EXPECT_EQ(scene.instances[1].object_to_world[3], 42.0f);
  EXPECT_EQ(scene.instances[2].object_to_world[3], 2.0f);
  EXPECT_EQ(scene.version, 7u);
}

TEST(CommitBuffer, BlasUploadAppendsGeometryAndReportsWhereItStarts) {
  TracerScene scene;
  scene.vertices.resize(10);
  scene.triangles.resize(4);
  scene.blas_nodes.resize(7);
  scene.blases.resize(1);
  BlasUpload up;
  up.blas_index = 1;
  up.vertex_offset = 10;
  up.vertices.resize(3);
  up.vertices[2].pos[0] = 5.0f;
  up.triangle_offset = 4;
  up.triangles = {{10, 11, 12, 0}};
  up.node_offset = 7;
  up.nodes.resize(1);
  up.blas = {7, 1, 4, 1};
  CommitBuffer c;
  c.add_blas(up);
  ChangeSet changes = apply_commit(c, scene);
  EXPECT_TRUE(changes.geometry);
  EXPECT_EQ(changes.vertices_from, 10u);
  EXPECT_EQ(changes.blases_from, 1u);
  ASSERT_EQ(scene.vertices.size(), 13u);
  EXPECT_EQ(scene.vertices[12].pos[0], 5.0f);
  ASSERT_EQ(scene.blases.size(), 2u);
  EXPECT_EQ(scene.blases[1].tri_offset, 4u);
}

TEST(CommitBuffer, RecordPastTheEndOfTheTracerSceneIsRejected) {
  TracerScene scene;
  scene.lights.resize(2);
  CommitBuffer c;
  c.set_light(5, KLight{});
  EXPECT_THROW(apply_commit(c, scene), std::invalid_argument);
}

TEST(CommitBuffer, EveryFrameAppliedInTurnMatchesTheMaster) {
  cohort::test::SceneChurn churn(1);
  TracerScene tracer;
  apply_commit(CommitBuffer::full(std::make_shared<TracerScene>(churn.master()), 0), tracer);
  for (uint64_t frame = 1; frame <= 300; ++frame) {
    apply_commit(churn.step(frame), tracer);
    std::string where;
    ASSERT_TRUE(same_tracer_scene(tracer, churn.master(), &where)) << "frame " << frame << ": " << where;
  }
}

TEST(CommitBuffer, MergedFramesApplyLikeTheFramesInTurn) {
  for (uint32_t seed = 1; seed <= 20; ++seed) {
    cohort::test::SceneChurn churn(seed);
    TracerScene tracer;
    apply_commit(CommitBuffer::full(std::make_shared<TracerScene>(churn.master()), 0), tracer);
    CommitBuffer accumulated;
    size_t summed_bytes = 0;
    for (uint64_t frame = 1; frame <= 40; ++frame) {
      CommitBuffer one = churn.step(frame);
      summed_bytes += one.bytes();
      accumulated.merge(one);
    }
    EXPECT_LE(accumulated.bytes(), summed_bytes);
    apply_commit(accumulated, tracer);
    std::string where;
    ASSERT_TRUE(same_tracer_scene(tracer, churn.master(), &where)) << "seed " << seed << ": " << where;
    EXPECT_EQ(tracer.version, 40u);
  }
}

TEST(CommitBuffer, FullResyncFollowedByRecordsAppliesBoth) {
  auto base = std::make_shared<TracerScene>();
  base->instances = {instance_at(0), instance_at(1)};
  CommitBuffer c = CommitBuffer::full(base, 3);
  CommitBuffer later;
  later.set_frame(4);
  later.set_instance(0, instance_at(9.0f));
  c.merge(later);
  TracerScene tracer;
  ChangeSet changes = apply_commit(c, tracer);
  EXPECT_TRUE(changes.full_resync);
  EXPECT_EQ(tracer.instances[0].object_to_world[3], 9.0f);
  EXPECT_EQ(tracer.version, 4u);
}

TEST(CommitBuffer, VertexColoursFollowTheVertexPool) {
  TracerScene scene;
  BlasUpload coloured;
  coloured.blas_index = 0;
  coloured.vertices.resize(3);
  coloured.vertex_colors = {0xFF0000FFu, 0xFF00FF00u, 0xFFFF0000u};
  coloured.triangles = {{0, 1, 2, 0}};
  coloured.nodes.resize(1);
  coloured.blas = {0, 1, 0, 1};
  BlasUpload white = coloured;   // a mesh without colours sends none
  white.blas_index = 1;
  white.vertex_offset = 3;
  white.vertex_colors.clear();
  white.triangles = {{3, 4, 5, 0}};
  white.triangle_offset = 1;
  white.node_offset = 1;
  white.blas = {1, 1, 1, 1};
  EXPECT_EQ(coloured.bytes(), white.bytes() + 3 * sizeof(KVertexColor));
  CommitBuffer c;
  c.add_blas(coloured);
  c.add_blas(white);
  apply_commit(c, scene);
  EXPECT_EQ(scene.vertex_colors,
            (std::vector<KVertexColor>{0xFF0000FFu, 0xFF00FF00u, 0xFFFF0000u, K_VERTEX_COLOR_WHITE,
                                       K_VERTEX_COLOR_WHITE, K_VERTEX_COLOR_WHITE}));

  // A full resync of a scene written without colours (an older producer) comes out white.
  auto bare = std::make_shared<TracerScene>();
  bare->vertices.resize(4);
  apply_commit(CommitBuffer::full(bare, 2), scene);
  EXPECT_EQ(scene.vertex_colors, std::vector<KVertexColor>(4, K_VERTEX_COLOR_WHITE));
}

TEST(CommitBuffer, BlasUploadWithColoursForSomeVerticesIsRejected) {
  TracerScene scene;
  BlasUpload up;
  up.blas_index = 0;
  up.vertices.resize(3);
  up.vertex_colors = {0xFFFFFFFFu, 0xFFFFFFFFu};
  up.blas = {0, 0, 0, 0};
  CommitBuffer c;
  c.add_blas(up);
  try {
    apply_commit(c, scene);
    FAIL() << "applied 2 colours for 3 vertices";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("BLAS 0 with 3 vertices but 2 vertex colours"), std::string::npos) << e.what();
  }
}
