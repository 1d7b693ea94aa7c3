// Entity shaderParm tint on every tracer the build has (doom3-content.md 6.3): `_color` (parm0-2) tints
// only materials whose stages read parm0-2 (`colored`), and only the entity that carries it. Three boxes
// seen from above, albedo view:
//   x = -60  `colored` material, world parms (1, 1, 1)        -> white
//   x =   0  `colored` material, parms (0.25, 0.5, 1)         -> (0.25, 0.5, 1)
//   x = +60  plain `rgb 0.5` material, parms (0.25, 0.5, 1)   -> 0.5 grey: it reads no parm
#include <gtest/gtest.h>

#include "cohort/scene/material_build.h"
#include "cohort/scene/material_file.h"
#include "test_scenes.h"
#include "test_tracers.h"

using namespace cohort;
using namespace cohort::test;

namespace {

class EntityTint : public EachTracer {};

scene::Scene three_boxes() {
  scene::Scene s;
  s.name = "tint";
  scene::MaterialTables tables;
  const scene::MaterialFile f = scene::parse_materials(
      "textures/tint { { blend diffusemap\n map _white\n colored } }\n"
      "textures/grey { { blend diffusemap\n map _white\n rgb 0.5 } }\n",
      "tint.mtr", tables);
  EXPECT_TRUE(f.warnings.empty()) << ::testing::PrintToString(f.warnings);
  scene::Vfs vfs;
  std::vector<std::string> warnings;
  scene::ImageLibrary images(vfs, s.images, warnings);
  for (const scene::MaterialDecl& d : f.materials) s.materials.push_back(scene::build_material(d, images, false));
  const int tint = s.find_material("textures/tint"), grey = s.find_material("textures/grey");
  s.meshes.push_back(box_mesh("tint_box", {20, 20, 20}, tint));
  s.meshes.push_back(box_mesh("grey_box", {20, 20, 20}, grey));
  const float parms[3] = {0.25f, 0.5f, 1.0f};
  const struct { int mesh; float x; bool tinted; } boxes[] = {{0, -60, false}, {0, 0, true}, {1, 60, true}};
  for (const auto& b : boxes) {
    scene::Entity e;
    e.name = "box";
    e.mesh = b.mesh;
    e.origin = {b.x, 0, 20};
    if (b.tinted) std::copy(parms, parms + 3, e.shader_parms);
    s.entities.push_back(e);
  }
  return s;
}

}  // namespace

TEST_P(EntityTint, ColorTintsOnlyTheEntityAndOnlyMaterialsThatReadParms) {
  const int n = 48;
  const float half_view = 120.0f;   // camera at z = 240 with tan 0.5
  core::FrameBuffer fb = render(*tracer_, three_boxes(), camera_looking_down({0, 0, 240}, 0.5f, n, n),
                                frame_params(K_MODE_ALBEDO, 4, 0, n));
  auto at = [&](float x) {
    return pixel(fb, int((x / half_view * 0.5f + 0.5f) * float(n)), n / 2);
  };
  const glm::vec3 plain = at(-60), tinted = at(0), grey = at(60);
  EXPECT_NEAR(plain.x, 1.0f, 1e-3f);
  EXPECT_NEAR(plain.y, 1.0f, 1e-3f);
  EXPECT_NEAR(plain.z, 1.0f, 1e-3f);
  EXPECT_NEAR(tinted.x, 0.25f, 1e-3f);
  EXPECT_NEAR(tinted.y, 0.5f, 1e-3f);
  EXPECT_NEAR(tinted.z, 1.0f, 1e-3f);
  EXPECT_NEAR(grey.x, 0.5f, 1e-3f);
  EXPECT_NEAR(grey.y, 0.5f, 1e-3f);
  EXPECT_NEAR(grey.z, 0.5f, 1e-3f);
}

INSTANTIATE_TEST_SUITE_P(Tracers, EntityTint, ::testing::ValuesIn(built_tracers()),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });
