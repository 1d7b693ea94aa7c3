// Animated materials on the commit path: which KMaterials and lights a frame re-sends, entity material
// instances for shaderParm tint, and their agreement with a fresh evaluation.
#include <gtest/gtest.h>

#include "cohort/core/world_sync.h"
#include "cohort/scene/cube_map.h"
#include "cohort/scene/map_loader.h"
#include "cohort/scene/material_build.h"
#include "cohort/scene/material_file.h"
#include "cohort/scene/render_world.h"
#include "cohort/test_support/scene_builders.h"

using namespace cohort;
using namespace cohort::core;

namespace {

const char* kMaterials =
    "table pulse { { 0, 1, 0.25 } }\n"
    "textures/still { { blend diffusemap\n map _white\n rgb 0.5 } }\n"
    "textures/scroll { { blend diffusemap\n map _white\n scroll time * 0.5, 0 } }\n"
    "textures/glow { { blend add\n map _white\n rgb pulse[ time ] } }\n"
    "textures/tint { { blend diffusemap\n map _white\n colored } }\n"
    "lights/flicker { { map _white\n rgb pulse[ time + parm4 ] } }\n";

struct AnimatedWorld {
  scene::Scene scene;
  int still = -1, scroll = -1, glow = -1, tint = -1, flicker = -1;
  int tint_mesh = -1, two_material_mesh = -1;

  AnimatedWorld() {
    scene::MaterialTables tables;
    scene::MaterialFile f = scene::parse_materials(kMaterials, "anim.mtr", tables);
    EXPECT_TRUE(f.warnings.empty());
    scene::Vfs vfs;
    std::vector<std::string> warnings;
    scene::ImageLibrary images(vfs, scene.images, warnings);
    for (const scene::MaterialDecl& d : f.materials) {
      scene.materials.push_back(scene::build_material(d, images, d.name.rfind("lights/", 0) == 0));
      const int index = int(scene.materials.size()) - 1;
      if (d.name == "textures/still") still = index;
      if (d.name == "textures/scroll") scroll = index;
      if (d.name == "textures/glow") glow = index;
      if (d.name == "textures/tint") tint = index;
      if (d.name == "lights/flicker") flicker = index;
    }
    scene::Mesh floor;
    floor.name = "_area0";
    test::add_quad(floor, still, {-64, -64, 0}, {0, -64, 0}, {0, 64, 0}, {-64, 64, 0}, {0, 0, 1});
    test::add_quad(floor, scroll, {0, -64, 0}, {64, -64, 0}, {64, 64, 0}, {0, 64, 0}, {0, 0, 1});
    test::add_quad(floor, glow, {-64, 64, 0}, {64, 64, 0}, {64, 64, 64}, {-64, 64, 64}, {0, -1, 0});
    test::add_world_mesh(scene, std::move(floor));
    scene.meshes.push_back(test::box_mesh("tinted_box", {8, 8, 8}, tint));
    tint_mesh = int(scene.meshes.size()) - 1;
    scene::Mesh two = test::box_mesh("two_box", {8, 8, 8}, tint);
    test::add_quad(two, still, {-8, -8, 9}, {8, -8, 9}, {8, 8, 9}, {-8, 8, 9}, {0, 0, 1});
    scene.meshes.push_back(std::move(two));
    two_material_mesh = int(scene.meshes.size()) - 1;
    scene::Light light = test::point_light({0, 0, 48}, {200, 200, 200});
    light.material = flicker;
    scene.lights.push_back(light);
  }
};

void set_time(scene::RenderWorld& world, int ms) {
  scene::RenderView view;
  view.origin = {0, -50, 30};
  view.time_ms = ms;
  world.RenderScene(view);
}

}  // namespace

TEST(AnimatedMaterials, OnlyMaterialsThatChangedAreSent) {
  AnimatedWorld w;
  scene::RenderWorld world(w.scene);
  WorldSync sync(world);
  world.TakeChanges();
  const uint32_t still = sync.kmaterial_index(w.still), scroll = sync.kmaterial_index(w.scroll),
                 glow = sync.kmaterial_index(w.glow);

  set_time(world, 250);   // scroll moves; pulse[0.25]: i = 0.75, 0.25 * v0 + 0.75 * v1
  commit::CommitBuffer frame = sync.sync(world.TakeChanges(), 1);
  EXPECT_EQ(frame.materials().size(), 2u);
  EXPECT_EQ(frame.materials().count(scroll), 1u);
  EXPECT_EQ(frame.materials().count(glow), 1u);
  EXPECT_EQ(frame.materials().count(still), 0u);
  EXPECT_NEAR(sync.master().materials[scroll].tex_transform[2], 0.125f, 1e-6f);
  EXPECT_NEAR(sync.master().materials[glow].emissive_color[0], 0.75f, 1e-6f);
  EXPECT_EQ(frame.lights().size(), 1u);   // the flickering light
  EXPECT_TRUE(frame.light_tree().has_value());

  set_time(world, 250);   // the same instant again: nothing to send
  frame = sync.sync(world.TakeChanges(), 2);
  EXPECT_EQ(frame.materials().size(), 0u);
  EXPECT_EQ(frame.lights().size(), 0u);
  EXPECT_FALSE(frame.light_tree().has_value());

  // A world whose materials do not animate sends no material at any time.
  scene::Scene still_scene = w.scene;
  for (scene::Material& m : still_scene.materials) m.registers.reset();
  scene::RenderWorld still_world(still_scene);
  WorldSync still_sync(still_world);
  still_world.TakeChanges();
  for (int ms : {100, 700, 1300}) {
    set_time(still_world, ms);
    EXPECT_EQ(still_sync.sync(still_world.TakeChanges(), uint64_t(ms)).materials().size(), 0u);
  }
}

TEST(AnimatedMaterials, FlickeringLightFollowsItsTable) {
  AnimatedWorld w;
  w.scene.lights[0].shader_parms[4] = 0.0f;
  w.scene.lights[0].color = glm::vec3(1.0f, 0.5f, 0.25f);
  scene::RenderWorld world(w.scene);
  WorldSync sync(world);
  world.TakeChanges();
  for (int ms : {0, 333, 500, 900}) {
    set_time(world, ms);
    sync.sync(world.TakeChanges(), uint64_t(ms) + 1);
    scene::MaterialTable pulse{{0, 1, 0.25f}, false, false};
    const float stage = pulse.lookup(ms * 0.001f);
    const float expected = stage < 0.001f ? 0.0f : stage;
    ASSERT_EQ(sync.master().lights.size(), 1u);
    const KLight& l = sync.master().lights[0];
    if (expected > 0.0f) { EXPECT_NEAR(l.color[1] / l.color[0], 0.5f, 1e-5f) << "at " << ms; }   // _color applies
    EXPECT_NEAR(l.color[0], GpuSceneOptions{}.light_scale * expected, 1e-5f) << "at " << ms;
  }
}

TEST(AnimatedMaterials, EntityParmsTintItsOwnMaterialInstance) {
  AnimatedWorld w;
  scene::RenderWorld world(w.scene);
  scene::RenderEntity plain;
  plain.model = w.tint_mesh;
  plain.origin = {-30, 0, 8};
  scene::RenderEntity tinted = plain;
  tinted.origin = {30, 0, 8};
  tinted.shader_parms[0] = 0.25f, tinted.shader_parms[1] = 0.5f, tinted.shader_parms[2] = 1.0f;
  scene::RenderEntity two = tinted;
  two.model = w.two_material_mesh;
  two.origin = {0, 30, 8};
  const int plain_handle = world.AddEntityDef(plain);
  const int tinted_handle = world.AddEntityDef(tinted);
  const int two_handle = world.AddEntityDef(two);
  WorldSync sync(world);
  world.TakeChanges();

  auto instance_of = [&](int handle) {
    for (const KInstance& i : sync.master().instances)
      if (i.entity == uint32_t(handle)) return i;
    ADD_FAILURE() << "no instance for entity " << handle;
    return KInstance{};
  };
  const KInstance p = instance_of(plain_handle), t = instance_of(tinted_handle), m2 = instance_of(two_handle);
  EXPECT_EQ(p.material_override, K_NONE);   // the world's parms: the shared material
  ASSERT_NE(t.material_override, K_NONE);
  const KMaterial& instance = sync.master().materials.at(t.material_override);
  EXPECT_FLOAT_EQ(instance.diffuse_color[0], 0.25f);
  EXPECT_FLOAT_EQ(instance.diffuse_color[1], 0.5f);
  EXPECT_FLOAT_EQ(instance.diffuse_color[2], 1.0f);
  const KMaterial& shared = sync.master().materials.at(sync.kmaterial_index(w.tint));
  EXPECT_FLOAT_EQ(shared.diffuse_color[0], 1.0f);
  EXPECT_NE(t.material_override, sync.kmaterial_index(w.tint));

  // Two materials on one model: its own BLAS whose tint triangles use the instance and the rest their own.
  EXPECT_EQ(m2.material_override, K_NONE);
  EXPECT_NE(m2.blas, t.blas);
  const KBlas& blas = sync.master().blases.at(m2.blas);
  std::set<uint32_t> used;
  for (uint32_t i = 0; i < blas.tri_count; ++i) used.insert(sync.master().triangles[blas.tri_offset + i].material);
  EXPECT_EQ(used.count(sync.kmaterial_index(w.still)), 1u);
  EXPECT_EQ(used.count(sync.kmaterial_index(w.tint)), 0u);
  ASSERT_EQ(used.size(), 2u);
  for (uint32_t m : used)
    if (m != sync.kmaterial_index(w.still)) { EXPECT_FLOAT_EQ(sync.master().materials.at(m).diffuse_color[0], 0.25f); }

  // New parms: the same slot re-evaluated, one material record, no new BLAS.
  tinted.shader_parms[0] = 0.75f;
  world.UpdateEntityDef(tinted_handle, tinted);
  commit::CommitBuffer frame = sync.sync(world.TakeChanges(), 1);
  EXPECT_EQ(frame.materials().size(), 1u);
  EXPECT_EQ(frame.materials().count(t.material_override), 1u);
  EXPECT_EQ(frame.blas_uploads().size(), 0u);
  EXPECT_FLOAT_EQ(sync.master().materials.at(t.material_override).diffuse_color[0], 0.75f);

  // Back to the world's parms: the shared material again; its slot is reused by the next instance.
  world.UpdateEntityDef(tinted_handle, plain);
  sync.sync(world.TakeChanges(), 2);
  EXPECT_EQ(instance_of(tinted_handle).material_override, K_NONE);
  world.UpdateEntityDef(plain_handle, tinted);
  sync.sync(world.TakeChanges(), 3);
  EXPECT_EQ(instance_of(plain_handle).material_override, t.material_override);
}

// The generated test map: its animated materials re-send at a new time, and crate_2's _color tints its
// own instance of the crate material while the other crates share the map's.
TEST(AnimatedMaterials, TestMapAnimatesAndTintsCrate2) {
  scene::Vfs vfs;
  vfs.add_search_path(std::string(COHORT_SOURCE_DIR) + "/assets/testmap");
  scene::RenderWorld world(scene::load_map(vfs, "testmap"));
  WorldSync sync(world);
  world.TakeChanges();
  const scene::Scene& s = world.scene();
  std::set<uint32_t> animated;
  for (const char* name : {"textures/testmap/pillar", "textures/testmap/vent", "textures/testmap/lightpanel_pulse"}) {
    const int m = s.find_material(name);
    ASSERT_GE(m, 0) << name;
    animated.insert(sync.kmaterial_index(m));
  }
  set_time(world, 700);
  commit::CommitBuffer frame = sync.sync(world.TakeChanges(), 1);
  std::set<uint32_t> sent;
  for (const auto& [index, material] : frame.materials()) sent.insert(index);
  EXPECT_EQ(sent, animated);
  EXPECT_EQ(frame.lights().size(), 1u);   // light_flicker

  const int crate2 = world.FindEntityDef("crate_2"), crate1 = world.FindEntityDef("crate_1");
  ASSERT_GE(crate2, 0);
  ASSERT_GE(crate1, 0);
  for (const KInstance& i : sync.master().instances) {
    if (i.entity == uint32_t(crate1)) { EXPECT_EQ(i.material_override, K_NONE); }
    if (i.entity != uint32_t(crate2)) continue;
    ASSERT_NE(i.material_override, K_NONE);
    const KMaterial& tinted = sync.master().materials.at(i.material_override);
    EXPECT_FLOAT_EQ(tinted.diffuse_color[0], 0.55f);
    EXPECT_FLOAT_EQ(tinted.diffuse_color[1], 0.8f);
    EXPECT_FLOAT_EQ(tinted.diffuse_color[2], 1.0f);
  }
}

// texgen wobbleSky reads time: the sky's KMaterial carries the engine's axes for the frame's time
// (X' and Y' in tex_transform, kernel/sky.h) and is re-sent as they turn.
TEST(AnimatedMaterials, WobblingSkyTurnsWithTime) {
  scene::Scene s;
  scene::MaterialTables tables;
  scene::MaterialFile f =
      scene::parse_materials("textures/sky/wobble { { cameraCubeMap env/none texgen wobbleSky 20 2 0.5 } }", "sky.mtr",
                             tables);
  scene::Vfs vfs;
  std::vector<std::string> warnings;
  scene::ImageLibrary images(vfs, s.images, warnings);
  s.materials.push_back(scene::build_material(f.materials.at(0), images, false));
  ASSERT_EQ(s.materials[0].blend, scene::BlendClass::Sky);
  scene::Mesh ceiling;
  ceiling.name = "_area0";
  test::add_quad(ceiling, 0, {-64, -64, 64}, {64, -64, 64}, {64, 64, 64}, {-64, 64, 64}, {0, 0, -1});
  test::add_world_mesh(s, std::move(ceiling));
  scene::RenderWorld world(s);
  WorldSync sync(world);
  world.TakeChanges();
  const uint32_t sky = sync.kmaterial_index(0);
  for (int ms : {4000, 15000}) {
    set_time(world, ms);
    commit::CommitBuffer frame = sync.sync(world.TakeChanges(), uint64_t(ms));
    EXPECT_EQ(frame.materials().count(sky), 1u) << "at " << ms;
    const glm::mat3 want = scene::wobble_sky_axes(20.0f, 2.0f, 0.5f, ms * 0.001f);
    const KMaterial& k = sync.master().materials[sky];
    EXPECT_EQ(k.blend, K_BLEND_SKY);
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(k.tex_transform[i], want[0][i], 1e-5f) << "X' at " << ms;
      EXPECT_NEAR(k.tex_transform[3 + i], want[1][i], 1e-5f) << "Y' at " << ms;
    }
  }
}

// An environment stage's colour is a register like any stage colour: the chrome's KMaterial carries
// the colour of the frame's time (env_color, its cube in env_tex1) and is re-sent as it changes; a
// missing cube still gets six placeholder faces, so the stage is drawn.
TEST(AnimatedMaterials, EnvironmentStageColourFollowsTime) {
  scene::Scene s;
  scene::MaterialTables tables;
  scene::MaterialFile f = scene::parse_materials(
      "textures/chrome { diffusemap _white { blend add cubeMap env/none texgen reflect rgb 0.25 * time } }",
      "chrome.mtr", tables);
  scene::Vfs vfs;
  std::vector<std::string> warnings;
  scene::ImageLibrary images(vfs, s.images, warnings);
  s.materials.push_back(scene::build_material(f.materials.at(0), images, false));
  ASSERT_GE(s.materials[0].environment_cube_image, 0);
  scene::Mesh floor;
  floor.name = "_area0";
  test::add_quad(floor, 0, {-64, -64, 0}, {64, -64, 0}, {64, 64, 0}, {-64, 64, 0}, {0, 0, 1});
  test::add_world_mesh(s, std::move(floor));
  scene::RenderWorld world(s);
  WorldSync sync(world);
  world.TakeChanges();
  const uint32_t chrome = sync.kmaterial_index(0);
  EXPECT_NE(sync.master().materials[chrome].env_tex1, 0u);
  for (int ms : {1000, 3000}) {
    set_time(world, ms);
    commit::CommitBuffer frame = sync.sync(world.TakeChanges(), uint64_t(ms));
    EXPECT_EQ(frame.materials().count(chrome), 1u) << "at " << ms;
    const KMaterial& k = sync.master().materials[chrome];
    EXPECT_EQ(k.blend, K_BLEND_OPAQUE);
    EXPECT_NE(k.env_tex1, 0u);
    EXPECT_EQ(k.flags & K_MAT_ENV_BY_NORMAL, 0u);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(k.env_color[c], 0.25f * float(ms) / 1000.0f, 1e-6f) << "at " << ms;
  }
}
