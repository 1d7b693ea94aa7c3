// Terrain blends (doom3-content.md 6.3): a material whose diffuse stages come in both vertex colour
// modes, one `vertexColor` and one `inverseVertexColor`, keeps both images: the second is shown where the
// first one's vertex colour leaves room. Other pairs keep the first stage only, as before.
#include <gtest/gtest.h>

#include "cohort/scene/image_library.h"
#include "cohort/scene/material_build.h"
#include "cohort/scene/material_file.h"
#include "cohort/scene/material_registers.h"

using namespace cohort::scene;

namespace {

const char* kTerrain = R"(
textures/terrain/rock_sand {
  bumpmap textures/terrain/rock_local
  { blend diffusemap  map textures/terrain/rock  vertexColor }
  { blend diffusemap  map textures/terrain/sand  inverseVertexColor }
}
textures/terrain/sand_rock {
  { blend diffusemap  map textures/terrain/sand  inverseVertexColor }
  { blend diffusemap  map textures/terrain/rock  vertexColor }
}
textures/terrain/same_mode {
  { blend diffusemap  map textures/terrain/rock  vertexColor }
  { blend diffusemap  map textures/terrain/sand  vertexColor }
}
textures/terrain/plain_first {
  diffusemap textures/terrain/rock
  { blend diffusemap  map textures/terrain/sand  inverseVertexColor }
}
)";

Material build(const std::string& name) {
  MaterialTables tables;
  MaterialFile file = parse_materials(kTerrain, "terrain.mtr", tables);
  static Vfs vfs;
  static std::vector<Image> images;
  static std::vector<std::string> warnings;
  static ImageLibrary library{vfs, images, warnings};
  for (const MaterialDecl& decl : file.materials)
    if (decl.name == name) return build_material(decl, library, false);
  ADD_FAILURE() << name << " not parsed";
  return {};
}

}  // namespace

TEST(VertexColorBlend, BothModesKeepBothImages) {
  for (const char* name : {"textures/terrain/rock_sand", "textures/terrain/sand_rock"}) {
    const Material m = build(name);
    EXPECT_GE(m.diffuse_image, 0) << name;
    EXPECT_GE(m.blend_diffuse_image, 0) << name;
    EXPECT_NE(m.blend_diffuse_image, m.diffuse_image) << name;
  }
  const Material rock_sand = build("textures/terrain/rock_sand");
  EXPECT_TRUE(rock_sand.vertex_color);
  EXPECT_FALSE(rock_sand.inverse_vertex_color);
  const Material sand_rock = build("textures/terrain/sand_rock");
  EXPECT_TRUE(sand_rock.inverse_vertex_color) << "the first diffuse stage sets the material's mode";
}

TEST(VertexColorBlend, OtherPairsKeepTheFirstStageOnly) {
  EXPECT_EQ(build("textures/terrain/same_mode").blend_diffuse_image, -1);
  EXPECT_EQ(build("textures/terrain/plain_first").blend_diffuse_image, -1);
}
