#include <gtest/gtest.h>

#include <filesystem>
#include <unistd.h>

#include "cohort/scene/map_loader.h"
#include "cohort/scene/render_world_stream.h"
#include "cohort/scene/scenario.h"
#include "cohort/test_support/test_scenes.h"

using namespace cohort::scene;

TEST(Scenario, DoorOpensFanSpinsLightFlickersFlashlightFollowsTheCamera) {
  RenderWorld world(cohort::test::small_test_map());
  const RenderEntity door0 = *world.EntityDef(1), fan0 = *world.EntityDef(2);
  Scenario scenario(world);
  scenario.frame(0);
  world.EndFrame();
  ASSERT_EQ(scenario.flashlight_handle(), 2);  // after the two map lights
  EXPECT_FALSE(world.LightDef(2)->point_light);
  EXPECT_EQ(world.EntityDef(1)->origin, door0.origin);  // not open yet at t = 0
  ChangeLog first = world.TakeChanges();
  EXPECT_EQ(first.entities, (std::set<int>{1, 2}));
  EXPECT_EQ(first.lights, (std::set<int>{0, 2}));
  EXPECT_TRUE(first.view);

  for (int i = 1; i <= 150; ++i) {
    scenario.frame(i);
    world.EndFrame();
  }
  // 2.5 s: the door is fully open, by the door's height less a lip.
  EXPECT_NEAR(world.EntityDef(1)->origin.z - door0.origin.z, 96.0f - 8.0f, 1e-3f);
  // The fan turned 450 degrees: its x axis points along +y.
  EXPECT_NEAR(world.EntityDef(2)->axis[0].y, 1.0f, 1e-4f);
  EXPECT_EQ(world.EntityDef(2)->origin, fan0.origin);
  // The flashlight sits with the camera.
  RenderView view = *world.view();
  EXPECT_LT(glm::length(world.LightDef(2)->origin - view.origin), 20.0f);
  EXPECT_EQ(world.LightDef(2)->axis, view.axis);
  EXPECT_EQ(view.time_ms, 2500);
  // The flicker varies over a second.
  float lo = 1, hi = 0;
  for (int i = 0; i < 10; ++i) {
    lo = std::min(lo, flicker_factor(i * 0.1));
    hi = std::max(hi, flicker_factor(i * 0.1));
  }
  EXPECT_LT(lo, 0.5f);
  EXPECT_EQ(hi, 1.0f);
}

TEST(Scenario, RecordedAndReplayedGivesTheSameWorldAsRunningIt) {
  auto file = std::filesystem::temp_directory_path() / ("cohort_scenario_" + std::to_string(::getpid()) + ".cds");
  RenderWorld direct(cohort::test::small_test_map());
  run_scenario(direct, 90);
  {
    RenderWorld recorded(cohort::test::small_test_map());
    Recorder recorder(recorded, file, "small");
    run_scenario(recorder, 90);
    recorder.finish();
  }
  Player player(file);
  RenderWorld replayed(cohort::test::small_test_map());
  while (player.play_frame(replayed)) {
  }
  EXPECT_EQ(player.frames_played(), 90u);
  ASSERT_EQ(direct.entity_defs().size(), replayed.entity_defs().size());
  for (size_t i = 0; i < direct.entity_defs().size(); ++i) EXPECT_EQ(direct.entity_defs()[i], replayed.entity_defs()[i]);
  ASSERT_EQ(direct.light_defs().size(), replayed.light_defs().size());
  for (size_t i = 0; i < direct.light_defs().size(); ++i) EXPECT_EQ(direct.light_defs()[i], replayed.light_defs()[i]);
  EXPECT_EQ(direct.view(), replayed.view());
  std::filesystem::remove(file);
}

TEST(Scenario, MissingNamesAreListedInOneError) {
  Scene s = cohort::test::small_test_map();
  s.entities[2].name = "something_else";
  s.lights[0].name = "other_light";
  RenderWorld world(std::move(s));
  try {
    Scenario scenario(world);
    FAIL() << "no error";
  } catch (const ScenarioError& e) {
    std::string what = e.what();
    EXPECT_NE(what.find("fan_spin"), std::string::npos) << what;
    EXPECT_NE(what.find("light_flicker"), std::string::npos) << what;
    EXPECT_EQ(what.find("door_main"), std::string::npos) << what;
  }
}

// The test map's walkers play their walk anim and walk a circle; a recording carries their joints.
TEST(Scenario, WalkersPlayTheirAnimAndTheStreamCarriesTheirJoints) {
  Vfs vfs;
  const Scene map = load_map(vfs, std::string(COHORT_SOURCE_DIR) + "/assets/testmap/maps/testmap.map");
  RenderWorld direct(map);
  Scenario scenario(direct);
  ASSERT_EQ(scenario.walker_handles().size(), 2u);
  const int walker = scenario.walker_handles()[0];
  const RenderEntity start = *direct.EntityDef(walker);
  EXPECT_TRUE(start.joints.empty());  // the map seeds the bind pose
  scenario.frame(0);
  const RenderEntity at0 = *direct.EntityDef(walker);
  for (int i = 1; i <= 30; ++i) scenario.frame(i);
  const RenderEntity at30 = *direct.EntityDef(walker);
  ASSERT_EQ(at0.joints.size(), map.meshes[size_t(start.model)].skin->joint_count);
  ASSERT_EQ(at30.joints.size(), at0.joints.size());
  EXPECT_NE(at0.joints, at30.joints) << "the anim plays";
  EXPECT_EQ(at0.origin, start.origin);
  EXPECT_GT(glm::length(at30.origin - start.origin), 10.0f) << "it walks (0.5 s at 40 units/s)";
  EXPECT_NEAR(glm::length(at30.origin - (start.origin + start.axis[1] * 40.0f)), 40.0f, 1e-3f) << "on its circle";

  auto file = std::filesystem::temp_directory_path() / ("cohort_walkers_" + std::to_string(::getpid()) + ".cds");
  {
    RenderWorld recorded(map);
    Recorder recorder(recorded, file, "testmap");
    run_scenario(recorder, 31);
    recorder.finish();
  }
  Player player(file);
  RenderWorld replayed(map);
  while (player.play_frame(replayed)) {
  }
  EXPECT_EQ(*replayed.EntityDef(walker), at30);
  std::filesystem::remove(file);
}
