#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <random>
#include <filesystem>
#include <limits>
#include <unistd.h>

#include "cohort/commit/array_diff.h"
#include "cohort/commit/commit_channel.h"
#include "cohort/core/gpu_scene.h"
#include "cohort/core/light_sampling.h"
#include "cohort/core/scene_queries.h"
#include "cohort/core/world_sync.h"
#include "cohort/scene/map_loader.h"
#include "cohort/scene/render_world_stream.h"
#include "cohort/scene/scenario.h"
#include "cohort/test_support/scene_builders.h"
#include "cohort/test_support/test_scenes.h"

using namespace cohort;
using namespace cohort::core;
using scene::RenderWorld;

namespace {

// The world's current state as a plain scene model, for compile_scene to compare against.
scene::Scene scene_of(const RenderWorld& world) {
  scene::Scene s = world.scene();
  s.entities.clear();
  for (size_t h = 0; h < world.entity_defs().size(); ++h) {
    scene::Entity e;
    if (const auto& def = world.entity_defs()[h]) {
      e.mesh = def->model;
      e.origin = def->origin;
      e.axis = def->axis;
      e.no_shadows = def->no_shadows;
    }
    s.entities.push_back(e);
  }
  s.lights.clear();
  for (size_t h = 0; h < world.light_defs().size(); ++h)
    if (world.light_defs()[h]) s.lights.push_back(world.scene_light(int(h)));
  return s;
}

// A tracer's channel as the Renderer keeps one: its first commit is a full resync to the master.
std::shared_ptr<commit::CommitChannel> channel_of(WorldSync& sync, size_t budget = 32u << 20) {
  return std::make_shared<commit::CommitChannel>(budget, sync.snapshot(), sync.master().version);
}

// One frame's records to every channel, with the master's snapshot for any full resync.
void publish(WorldSync& sync, const commit::CommitBuffer& records,
             const std::vector<std::shared_ptr<commit::CommitChannel>>& channels) {
  for (const auto& channel : channels) channel->publish(records, [&] { return sync.snapshot(); });
}

std::string first_difference(const commit::TracerScene& a, const commit::TracerScene& b) {
  std::string where;
  return commit::same_tracer_scene(a, b, &where) ? "" : where;
}

// Calls of every kind beyond the scenario: a texture, material and model defined at run time, an
// entity using them, an entity and a light freed.
void define_and_free(scene::RenderWorldApi& world, int frame) {
  if (frame == 10) {
    int tex = world.DefineTexture(test::checker("textures/test/crate", 8));
    scene::Material m;
    m.name = "textures/test/crate";
    m.diffuse_image = tex;
    m.vertex_color = true;
    int mat = world.DefineMaterial(m);
    scene::Mesh crate_mesh = test::box_mesh("crate", {8, 8, 8}, mat);   // vertex colours: a ramp of reds
    for (uint32_t v = 0; v < crate_mesh.vertices.size(); ++v) crate_mesh.colors.push_back(0xFF000000u | (v * 30u + 10u));
    world.DefineModel(crate_mesh);
    scene::RenderEntity crate;
    crate.model_name = "crate";
    crate.origin = {40, 40, 8};
    world.AddEntityDef(crate);
  }
  if (frame == 20) world.FreeLightDef(world.FindLightDef("light_fill"));
  if (frame == 30) {
    scene::RenderEntity moved = *world.EntityDef(3);
    moved.origin.x += 16;
    moved.custom_shader = 0;
    world.UpdateEntityDef(3, moved);
  }
}

void run_frames(scene::RenderWorldApi& world, int frames) {
  scene::Scenario scenario(world);
  for (int f = 0; f < frames; ++f) {
    define_and_free(world, f);
    scenario.frame(f);
    world.EndFrame();
  }
}

}  // namespace

TEST(WorldSync, SyncedMasterEqualsAFreshCompileOfTheSameState) {
  RenderWorld world(test::small_test_map());
  WorldSync sync(world);
  scene::Scenario scenario(world);
  for (int f = 0; f < 100; ++f) {
    scenario.frame(f);
    world.EndFrame();
    sync.sync(world.TakeChanges(), uint64_t(f + 1));
  }
  CompiledScene fresh = compile_scene(scene_of(world));
  commit::TracerScene expected = fresh.tracer_scene;
  expected.camera = sync.master().camera;
  expected.version = sync.master().version;
  // Moving entities refit the TLAS rather than rebuild it, so the master's tree and instance order may
  // differ from a fresh build's: the same instances, and a TLAS that finds the same surfaces.
  auto by_entity = [](std::vector<KInstance> v) {
    std::sort(v.begin(), v.end(), [](const KInstance& a, const KInstance& b) {
      return std::memcmp(&a, &b, sizeof(KInstance)) < 0;
    });
    return v;
  };
  const std::vector<KInstance> master_instances = by_entity(sync.master().instances);
  const std::vector<KInstance> fresh_instances = by_entity(expected.instances);
  ASSERT_EQ(master_instances.size(), fresh_instances.size());
  EXPECT_EQ(std::memcmp(master_instances.data(), fresh_instances.data(), master_instances.size() * sizeof(KInstance)), 0);
  commit::TracerScene master = sync.master();
  expected.instances = master.instances;
  expected.tlas_nodes = master.tlas_nodes;
  EXPECT_EQ(first_difference(master, expected), "");
  EXPECT_EQ(sync.master().lights.size(), 3u);  // two map lights and the flashlight

  SceneQueries refit(std::make_shared<commit::TracerScene>(sync.master()));
  SceneQueries rebuilt(std::make_shared<commit::TracerScene>(fresh.tracer_scene));
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  const glm::vec3 eye(sync.master().camera.origin[0], sync.master().camera.origin[1], sync.master().camera.origin[2]);
  int hits = 0;
  for (int i = 0; i < 2000; ++i) {
    const glm::vec3 d = glm::normalize(glm::vec3(unit(rng), unit(rng), 0.5f * unit(rng)) + glm::vec3(1e-3f));
    const std::optional<PickHit> a = refit.pick(eye, d), b = rebuilt.pick(eye, d);
    ASSERT_EQ(a.has_value(), b.has_value()) << "ray " << i;
    if (!a) continue;
    ++hits;
    EXPECT_NEAR(a->distance, b->distance, 1e-3f * std::max(1.0f, b->distance)) << "ray " << i;
    EXPECT_EQ(a->entity, b->entity) << "ray " << i;
  }
  EXPECT_GT(hits, 500);  // 784 of the 2,000 rays hit something from this eye
}

// Entities that only move get their instances updated in place and the TLAS refit, not rebuilt; a new
// or freed entity rebuilds it.
TEST(WorldSync, MovingEntitiesRefitTheTlasAndNewOnesRebuildIt) {
  RenderWorld world(test::small_test_map());
  WorldSync sync(world);
  scene::RenderEntity fan = *world.EntityDef(2);
  fan.origin.z += 1.0f;
  world.UpdateEntityDef(2, fan);
  sync.sync(world.TakeChanges(), 1);
  EXPECT_TRUE(sync.last_stats().tlas_refit);
  EXPECT_FALSE(sync.last_stats().tlas_rebuilt);
  scene::RenderEntity copy = fan;
  copy.origin.x += 32.0f;
  world.AddEntityDef(copy);
  sync.sync(world.TakeChanges(), 2);
  EXPECT_TRUE(sync.last_stats().tlas_rebuilt);
  EXPECT_FALSE(sync.last_stats().tlas_refit);
}

// An emitting entity that only moves takes the TLAS refit path; its emissive triangles (world space)
// and the emissive tree must still follow it.
TEST(WorldSync, MovingAnEmittingEntityMovesItsEmissiveTriangles) {
  scene::Scene map = test::small_test_map();
  scene::Material panel;
  panel.name = "panel";
  panel.emitter = true;
  panel.emissive_color = glm::vec4(2.0f, 1.5f, 0.8f, 1.0f);
  map.materials.push_back(panel);
  RenderWorld world(map);
  scene::RenderEntity fan = *world.EntityDef(2);
  fan.custom_shader = int(map.materials.size()) - 1;
  world.UpdateEntityDef(2, fan);
  WorldSync sync(world);
  const auto emitters_of_fan = [&] {
    std::vector<KEmissiveTriangle> out;
    for (const KEmissiveTriangle& e : sync.master().emissive_triangles)
      if (sync.master().instances[e.instance].entity == 2u) out.push_back(e);
    return out;
  };
  const std::vector<KEmissiveTriangle> before = emitters_of_fan();
  ASSERT_FALSE(before.empty());
  fan.origin.z += 5.0f;
  world.UpdateEntityDef(2, fan);
  sync.sync(world.TakeChanges(), 1);
  ASSERT_TRUE(sync.last_stats().tlas_refit);
  const std::vector<KEmissiveTriangle> after = emitters_of_fan();
  ASSERT_EQ(after.size(), before.size());
  for (size_t i = 0; i < after.size(); ++i) EXPECT_NEAR(after[i].p0[2], before[i].p0[2] + 5.0f, 1e-3f);
  commit::TracerScene fresh = sync.master();
  rebuild_light_sampling(fresh);
  EXPECT_EQ(first_difference(fresh, sync.master()), "");
}

TEST(WorldSync, ReplayedStreamGivesTheSameTracerSceneEveryFrame) {
  const int frames = 60;
  auto file = std::filesystem::temp_directory_path() / ("cohort_world_sync_" + std::to_string(::getpid()) + ".cds");
  {
    RenderWorld recorded(test::small_test_map());
    scene::Recorder recorder(recorded, file, "small");
    run_frames(recorder, frames);
    recorder.finish();
  }
  RenderWorld direct(test::small_test_map());
  WorldSync direct_sync(direct);
  RenderWorld replayed(test::small_test_map());
  WorldSync replay_sync(replayed);
  auto channel = channel_of(replay_sync);
  commit::TracerScene tracer;

  scene::Player player(file);
  scene::Scenario scenario(direct);
  for (int f = 0; f < frames; ++f) {
    define_and_free(direct, f);
    scenario.frame(f);
    direct.EndFrame();
    direct_sync.sync(direct.TakeChanges(), uint64_t(f + 1));
    ASSERT_TRUE(player.play_frame(replayed));
    publish(replay_sync, replay_sync.sync(replayed.TakeChanges(), uint64_t(f + 1)), {channel});
    ASSERT_EQ(first_difference(direct_sync.master(), replay_sync.master()), "") << "frame " << f;
    commit::apply_commit(channel->begin_frame(), tracer);
    ASSERT_EQ(first_difference(tracer, replay_sync.master()), "") << "tracer copy, frame " << f;
  }
  scene::RenderWorld scratch(test::small_test_map());
  EXPECT_FALSE(player.play_frame(scratch));
  std::filesystem::remove(file);
}

TEST(WorldSync, TracersThatSkipFramesConvergeToTheMaster) {
  RenderWorld world(test::small_test_map());
  WorldSync sync(world);
  const int periods[] = {1, 4, 7, 1000};
  std::vector<std::shared_ptr<commit::CommitChannel>> channels;
  std::vector<commit::TracerScene> tracers(std::size(periods));
  for (size_t t = 0; t < std::size(periods); ++t) channels.push_back(channel_of(sync));
  scene::Scenario scenario(world);
  const int frames = 80;
  for (int f = 0; f < frames; ++f) {
    define_and_free(world, f);
    scenario.frame(f);
    world.EndFrame();
    publish(sync, sync.sync(world.TakeChanges(), uint64_t(f + 1)), channels);
    for (size_t t = 0; t < std::size(periods); ++t)
      if ((f + 1) % periods[t] == 0 || f + 1 == frames) commit::apply_commit(channels[t]->begin_frame(), tracers[t]);
  }
  for (size_t t = 0; t < std::size(periods); ++t) {
    EXPECT_EQ(first_difference(tracers[t], sync.master()), "") << "period " << periods[t];
    EXPECT_EQ(channels[t]->stats().overflows, 0u);
  }
  EXPECT_LT(channels[1]->stats().total_bytes, channels[0]->stats().total_bytes);
}

TEST(WorldSync, RuntimeModelMaterialAndTextureReachTheTracerScene) {
  RenderWorld world(test::small_test_map());
  WorldSync sync(world);
  const uint32_t default_material = sync.kmaterial_index(-1);
  const size_t blases_before = sync.master().blases.size();
  define_and_free(world, 10);
  commit::CommitBuffer records = sync.sync(world.TakeChanges(), 1);
  ASSERT_EQ(records.blas_uploads().size(), 1u);
  EXPECT_EQ(sync.last_stats().blas_builds, 1u);
  EXPECT_EQ(sync.master().blases.size(), blases_before + 1);

  const int crate_material = world.scene().find_material("textures/test/crate");
  const uint32_t kmat = sync.kmaterial_index(crate_material);
  EXPECT_EQ(kmat, default_material + 1);  // after the default one, which keeps its index
  const commit::BlasUpload& up = records.blas_uploads()[0];
  for (const KTriangle& t : up.triangles) {
    EXPECT_EQ(t.material, kmat);
    EXPECT_GE(t.v0, up.vertex_offset);
    EXPECT_LT(t.v2, up.vertex_offset + up.vertices.size());
  }
  const KMaterial& m = sync.master().materials.at(kmat);
  ASSERT_NE(m.diffuse_tex, K_NONE);
  const KTexture& tex = sync.master().textures.at(m.diffuse_tex);
  EXPECT_EQ(tex.width, 8u);
  const scene::Image& image = world.scene().images.back();
  uint32_t first_texel = uint32_t(image.rgba[0]) | uint32_t(image.rgba[1]) << 8 | uint32_t(image.rgba[2]) << 16 |
                         uint32_t(image.rgba[3]) << 24;
  EXPECT_EQ(sync.master().texels.at(tex.offset), first_texel);
  // Its vertex colours travel with the upload and sit beside its vertices in the master; the map's own
  // geometry, which has none, is white there.
  ASSERT_EQ(up.vertex_colors.size(), up.vertices.size());
  EXPECT_EQ(up.vertex_colors[2], 0xFF000000u | 70u);
  ASSERT_EQ(sync.master().vertex_colors.size(), sync.master().vertices.size());
  EXPECT_EQ(sync.master().vertex_colors.at(up.vertex_offset + 2), 0xFF000000u | 70u);
  EXPECT_EQ(sync.master().vertex_colors.front(), K_VERTEX_COLOR_WHITE);
  EXPECT_NE(m.flags & K_MAT_VERTEX_COLOR, 0u);
  // The crate is instanced with its handle.
  bool found = false;
  for (const KInstance& inst : sync.master().instances) found |= inst.entity == 3 && inst.blas == up.blas_index;
  EXPECT_TRUE(found);
}

TEST(WorldSync, OverflowingTheBudgetGivesAFullResyncThatConverges) {
  RenderWorld world(test::small_test_map());
  WorldSync sync(world);
  auto channel = channel_of(sync, 1024);
  commit::TracerScene tracer;
  commit::apply_commit(channel->begin_frame(), tracer);
  scene::Scenario scenario(world);
  for (int f = 0; f < 12; ++f) {
    define_and_free(world, f);
    scenario.frame(f);
    world.EndFrame();
    publish(sync, sync.sync(world.TakeChanges(), uint64_t(f + 1)), {channel});
  }
  const commit::CommitBuffer& commit = channel->begin_frame();
  EXPECT_TRUE(commit.is_full_resync());
  commit::apply_commit(commit, tracer);
  EXPECT_EQ(first_difference(tracer, sync.master()), "");
  EXPECT_GE(channel->stats().overflows, 1u);
}

TEST(WorldSync, OnlyMovedEntitiesAndTheTlasAreSent) {
  RenderWorld world(test::small_test_map());
  WorldSync sync(world);
  scene::RenderEntity fan = *world.EntityDef(2);
  fan.origin.z += 1.0f;
  world.UpdateEntityDef(2, fan);
  commit::CommitBuffer records = sync.sync(world.TakeChanges(), 1);
  EXPECT_TRUE(records.tlas().has_value());
  EXPECT_TRUE(records.lights().empty());
  EXPECT_TRUE(records.materials().empty());
  EXPECT_TRUE(records.blas_uploads().empty());
  EXPECT_GE(records.instances().size(), 1u);
  EXPECT_LE(records.instances().size(), sync.master().instances.size());
  commit::CommitBuffer nothing = sync.sync(world.TakeChanges(), 2);
  EXPECT_TRUE(nothing.empty());
}

// Model files reach the tracers' scene as entity instances; instances of one model (and skin) share
// one BLAS, another skin gets its own.
TEST(WorldSync, ModelFileInstancesShareOneBlas) {
  const std::filesystem::path base = std::filesystem::path(COHORT_SOURCE_DIR) / "assets/testmap";
  if (!std::filesystem::exists(base / "maps/testmap.map")) GTEST_SKIP() << "assets/testmap is not generated";
  scene::Vfs vfs;
  vfs.add_search_path(base);
  RenderWorld world(scene::load_map(vfs, "testmap"));
  WorldSync sync(world);
  auto blas_of = [&](const char* name) {
    int handle = world.FindEntityDef(name);
    EXPECT_GE(handle, 0) << name;
    for (const KInstance& instance : sync.master().instances)
      if (instance.entity == uint32_t(handle)) return instance.blas;
    ADD_FAILURE() << name << " has no instance";
    return K_NONE;
  };
  EXPECT_NE(blas_of("lamp_1"), K_NONE);
  EXPECT_EQ(blas_of("lamp_1"), blas_of("lamp_2"));
  EXPECT_EQ(blas_of("wedge_1"), blas_of("wedge_2"));
  EXPECT_NE(blas_of("walker_1"), blas_of("walker_2"));
  EXPECT_NE(blas_of("lamp_1"), blas_of("wedge_1"));
}

// A light moved through the world reaches the tracers as its light record plus a new light tree whose
// leaf box for it moved with it; the tree stays the one a fresh build gives.
TEST(WorldSync, MovedLightSendsItsLightAndANewLightTree) {
  RenderWorld world(test::small_test_map());
  WorldSync sync(world);
  ASSERT_EQ(sync.master().light_nodes.size(), 2 * sync.master().lights.size() - 1);
  const int fill = world.FindLightDef("light_fill");
  ASSERT_GE(fill, 0);
  scene::RenderLight moved = *world.LightDef(fill);
  moved.origin.x += 500.0f;
  world.UpdateLightDef(fill, moved);
  const std::vector<KLightNode> before = sync.master().light_nodes;
  commit::CommitBuffer records = sync.sync(world.TakeChanges(), 1);
  ASSERT_TRUE(records.light_tree().has_value());
  EXPECT_EQ(records.lights().size(), 1u);
  EXPECT_EQ(records.light_tree()->size(), before.size());
  EXPECT_NE(std::memcmp(records.light_tree()->data(), before.data(), before.size() * sizeof(KLightNode)), 0);
  const std::vector<KLightNode> fresh = build_light_tree(sync.master().lights);
  EXPECT_EQ(std::memcmp(fresh.data(), sync.master().light_nodes.data(), fresh.size() * sizeof(KLightNode)), 0);
  // Moving nothing sends no tree.
  EXPECT_FALSE(sync.sync(world.TakeChanges(), 2).light_tree().has_value());
}

// A light def turned bad by the game (zero radius, an origin far outside any map; RenderWorld itself
// refuses NaN) is left out with a warning, and comes
// back when it is fixed.
TEST(WorldSync, LightWithADefectIsSkippedUntilFixed) {
  RenderWorld world(test::small_test_map());
  WorldSync sync(world);
  const size_t lights = sync.master().lights.size();
  const int fill = world.FindLightDef("light_fill");
  const scene::RenderLight good = *world.LightDef(fill);
  scene::RenderLight bad = good;
  bad.radius = glm::vec3(0.0f, 200.0f, 200.0f);
  world.UpdateLightDef(fill, bad);
  sync.sync(world.TakeChanges(), 1);
  EXPECT_EQ(sync.master().lights.size(), lights - 1);
  EXPECT_EQ(sync.last_stats().lights_skipped, 1u);
  EXPECT_EQ(sync.master().light_nodes.size(), 2 * (lights - 1) - 1);
  bad = good;
  bad.origin.y = 1e12f;
  world.UpdateLightDef(fill, bad);
  sync.sync(world.TakeChanges(), 2);
  EXPECT_EQ(sync.master().lights.size(), lights - 1);
  world.UpdateLightDef(fill, good);
  sync.sync(world.TakeChanges(), 3);
  EXPECT_EQ(sync.master().lights.size(), lights);
}
