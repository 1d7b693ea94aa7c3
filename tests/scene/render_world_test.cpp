#include <gtest/gtest.h>

#include <algorithm>

#include "cohort/scene/render_world.h"
#include "cohort/test_support/scene_builders.h"
#include "cohort/test_support/test_scenes.h"

using namespace cohort::scene;

TEST(RenderWorld, SeededFromASceneGivesMapEntitiesAndLightsTheirIndexAsHandle) {
  RenderWorld world(cohort::test::small_test_map());
  EXPECT_EQ(world.FindEntityDef("door_main"), 1);
  EXPECT_EQ(world.FindEntityDef("fan_spin"), 2);
  EXPECT_EQ(world.FindLightDef("light_flicker"), 0);
  EXPECT_EQ(world.FindEntityDef("no_such_entity"), -1);
  ASSERT_NE(world.EntityDef(1), nullptr);
  EXPECT_EQ(world.EntityDef(1)->model, 1);
  EXPECT_EQ(world.EntityDef(1)->origin, glm::vec3(128, 0, 48));
  const RenderLight* flicker = world.LightDef(0);
  ASSERT_NE(flicker, nullptr);
  EXPECT_FLOAT_EQ(flicker->shader_parms[kShaderParmGreen], 0.8f);
  EXPECT_TRUE(world.changes().empty());
}

TEST(RenderWorld, HandlesAreTheLowestFreeOneLikeTheEngine) {
  RenderWorld world(cohort::test::small_test_map());
  RenderEntity box;
  box.model_name = "fan_spin";
  EXPECT_EQ(world.AddEntityDef(box), 3);
  EXPECT_EQ(world.AddEntityDef(box), 4);
  world.FreeEntityDef(1);
  EXPECT_EQ(world.FindEntityDef("door_main"), -1);
  EXPECT_EQ(world.AddEntityDef(box), 1);
  EXPECT_EQ(world.AddEntityDef(box), 5);
  EXPECT_EQ(world.EntityDef(5)->model, 2);  // the name was resolved
  EXPECT_TRUE(world.EntityDef(5)->model_name.empty());
  RenderLight light;
  EXPECT_EQ(world.AddLightDef(light), 2);
  world.FreeLightDef(0);
  EXPECT_EQ(world.AddLightDef(light), 0);
}

TEST(RenderWorld, ChangeLogNamesWhatChangedAndIsClearedWhenTaken) {
  RenderWorld world(cohort::test::small_test_map());
  RenderEntity door = *world.EntityDef(1);
  door.origin.z += 10;
  world.UpdateEntityDef(1, door);
  world.FreeLightDef(1);
  RenderView view;
  world.RenderScene(view);
  world.EndFrame();
  ChangeLog log = world.TakeChanges();
  EXPECT_EQ(log.entities, std::set<int>{1});
  EXPECT_EQ(log.freed_lights, std::set<int>{1});
  EXPECT_TRUE(log.view);
  EXPECT_EQ(log.frames_ended, 1);
  EXPECT_TRUE(world.changes().empty());
}

TEST(RenderWorld, FreedAndReAddedInOneFrameIsInBothSets) {
  RenderWorld world(cohort::test::small_test_map());
  RenderEntity def = *world.EntityDef(2);
  world.FreeEntityDef(2);
  EXPECT_EQ(world.AddEntityDef(def), 2);
  ChangeLog log = world.TakeChanges();
  EXPECT_EQ(log.freed_entities, std::set<int>{2});
  EXPECT_EQ(log.entities, std::set<int>{2});
}

TEST(RenderWorld, DefinitionsByNameReplaceOrAppend) {
  RenderWorld world(cohort::test::small_test_map());
  Material m = world.scene().materials[0];
  m.diffuse_color = glm::vec4(0.5f);
  EXPECT_EQ(world.DefineMaterial(m), 0);
  m.name = "textures/test/new";
  EXPECT_EQ(world.DefineMaterial(m), 2);
  EXPECT_EQ(world.DefineTexture(cohort::test::checker("textures/test/other", 2)), 1);
  EXPECT_EQ(world.DefineModel(cohort::test::box_mesh("crate", {8, 8, 8}, 2)), 3);
  ChangeLog log = world.TakeChanges();
  EXPECT_EQ(log.materials, (std::set<int>{0, 2}));
  EXPECT_EQ(log.textures, std::set<int>{1});
  EXPECT_EQ(log.models, std::set<int>{3});
}

TEST(RenderWorld, CallsThatDoNotFitTheStateAreRejectedWithAClearError) {
  RenderWorld world(cohort::test::small_test_map());
  RenderEntity def;
  EXPECT_THROW(world.UpdateEntityDef(42, def), RenderWorldError);
  EXPECT_THROW(world.FreeLightDef(-1), RenderWorldError);
  def.model_name = "models/missing";
  try {
    world.AddEntityDef(def);
    FAIL() << "no error";
  } catch (const RenderWorldError& e) {
    EXPECT_NE(std::string(e.what()).find("models/missing"), std::string::npos);
  }
  def = {};
  def.model = 99;
  EXPECT_THROW(world.AddEntityDef(def), RenderWorldError);
  def.model = 1;
  def.origin.x = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(world.AddEntityDef(def), RenderWorldError);
  Image bad = cohort::test::checker("bad", 4);
  bad.rgba.pop_back();
  EXPECT_THROW(world.DefineTexture(bad), RenderWorldError);
  Mesh broken = cohort::test::box_mesh("broken", {1, 1, 1}, 0);
  broken.indices.push_back(100);
  EXPECT_THROW(world.DefineModel(broken), RenderWorldError);
  Material reflective;
  reflective.name = "textures/test/reflective";
  reflective.environment_cube_image = std::max(0, int(world.scene().images.size()) - 2);   // six faces from there
  try {
    world.DefineMaterial(reflective);
    FAIL() << "no error";
  } catch (const RenderWorldError& e) {
    EXPECT_NE(std::string(e.what()).find("environment cube faces"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(world.changes().empty());
}
