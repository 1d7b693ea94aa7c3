#include <gtest/gtest.h>

#include "cohort/scene/material_file.h"
#include "test_files.h"

using namespace cohort::scene;
using cohort::scene::test::data_dir;
using cohort::scene::test::read_text;

namespace {

const MaterialDecl* find(const MaterialFile& f, const std::string& name) {
  for (const auto& m : f.materials)
    if (m.name == name) return &m;
  return nullptr;
}

bool has_warning(const MaterialFile& f, const std::string& part) {
  for (const auto& w : f.warnings)
    if (w.find(part) != std::string::npos) return true;
  return false;
}

}  // namespace

TEST(MaterialParser, ShorthandsStagesAndImagePrograms) {
  MaterialTables tables;
  MaterialFile f = parse_materials(read_text(data_dir() / "base/materials/test.mtr"), "test.mtr", tables);
  EXPECT_EQ(f.materials.size(), 10u);  // skins, particles, tables and guides are not materials
  const MaterialDecl* floor = find(f, "textures/test/floor");
  ASSERT_NE(floor, nullptr);
  ASSERT_EQ(floor->stages.size(), 3u);
  EXPECT_EQ(floor->stages[0].role, StageRole::Diffuse);
  EXPECT_EQ(floor->stages[1].role, StageRole::Bump);
  EXPECT_EQ(floor->stages[1].image.function, "addnormals");
  ASSERT_EQ(floor->stages[1].image.inputs.size(), 2u);
  EXPECT_EQ(floor->stages[1].image.inputs[1].function, "heightmap");
  EXPECT_FLOAT_EQ(floor->stages[1].image.inputs[1].numbers.at(0), 4.0f);
  EXPECT_EQ(floor->stages[1].image.text(),
            "addnormals(textures/test/floor_local.tga, heightmap(textures/test/floor_h.tga, 4))");
  EXPECT_EQ(floor->stages[2].role, StageRole::Specular);
  EXPECT_EQ(floor->line, 13);
}

TEST(MaterialParser, BlendModesColoursAndTransforms) {
  MaterialTables tables;
  MaterialFile f = parse_materials(read_text(data_dir() / "base/materials/test.mtr"), "test.mtr", tables);
  const MaterialDecl* wall = find(f, "textures/test/wall");
  ASSERT_NE(wall, nullptr);
  ASSERT_EQ(wall->stages.size(), 3u);
  const MaterialStage& diffuse = wall->stages[0];
  EXPECT_EQ(diffuse.role, StageRole::Diffuse);
  EXPECT_EQ(diffuse.color, glm::vec4(0.5f, 0.5f, 0.5f, 1.0f));
  // scale 2, 4 then scroll 0.25, 0: the scroll applies first, in texture space, then the scale.
  EXPECT_FLOAT_EQ(diffuse.tex_transform[0], 2.0f);
  EXPECT_FLOAT_EQ(diffuse.tex_transform[4], 4.0f);
  EXPECT_FLOAT_EQ(diffuse.tex_transform[2], 0.5f);
  EXPECT_FLOAT_EQ(diffuse.tex_transform[5], 0.0f);
  EXPECT_EQ(wall->stages[2].role, StageRole::Ambient);
  EXPECT_EQ(wall->stages[2].blend, StageBlend::Add);
  EXPECT_FLOAT_EQ(wall->stages[2].color.r, 0.25f);

  const MaterialDecl* grate = find(f, "textures/test/grate");
  EXPECT_TRUE(grate->two_sided);
  EXPECT_TRUE(grate->no_shadows);
  EXPECT_TRUE(grate->stages[0].alpha_test);
  EXPECT_FLOAT_EQ(grate->stages[0].alpha_ref, 0.5f);

  const MaterialDecl* glass = find(f, "textures/test/glass");
  EXPECT_TRUE(glass->translucent);
  EXPECT_TRUE(glass->nonsolid);
  EXPECT_EQ(glass->stages[0].blend, StageBlend::AlphaBlend);
  EXPECT_FLOAT_EQ(glass->stages[0].color.a, 0.4f);

  EXPECT_EQ(find(f, "textures/test/decal")->stages[0].blend, StageBlend::Modulate);
  EXPECT_TRUE(find(f, "textures/test/decal")->no_shadows);
  EXPECT_TRUE(find(f, "textures/common/caulk")->stages.empty());
}

TEST(MaterialParser, TimeAndTablesCompileToRegistersWithoutWarnings) {
  MaterialTables tables;
  MaterialFile f = parse_materials(read_text(data_dir() / "base/materials/test.mtr"), "test.mtr", tables);
  ASSERT_EQ(tables.count("flickertable"), 1u);
  const MaterialDecl* panel = find(f, "textures/test/panel");
  EXPECT_FLOAT_EQ(panel->stages[0].color.r, 0.5f);  // flickertable[0], snapped
  EXPECT_FLOAT_EQ(panel->stages[0].tex_transform[0], 1.0f);  // rotate time*0.1 at time 0: identity
  EXPECT_FLOAT_EQ(panel->stages[0].tex_transform[1], 0.0f);
  EXPECT_EQ(panel->stages[0].registers.depends(), kDependsTime);
  for (const auto& w : f.warnings) EXPECT_EQ(w.find("material textures/test/panel"), std::string::npos) << w;
}

TEST(MaterialParser, LightMaterial) {
  MaterialTables tables;
  MaterialFile f = parse_materials(read_text(data_dir() / "base/materials/test.mtr"), "test.mtr", tables);
  const MaterialDecl* gel = find(f, "lights/test_gel");
  ASSERT_NE(gel, nullptr);
  EXPECT_EQ(gel->falloff_image.text(), "makeintensity(lights/test_falloff.tga)");
  ASSERT_EQ(gel->stages.size(), 1u);
  EXPECT_EQ(gel->stages[0].image.path, "lights/test_gel.tga");
}

TEST(MaterialParser, ErrorsInsideAMaterialBecomeWarningsWithFileLine) {
  MaterialTables tables;
  MaterialFile f = parse_materials(read_text(data_dir() / "base/materials/test.mtr"), "test.mtr", tables);
  const MaterialDecl* broken = find(f, "textures/test/broken");
  ASSERT_NE(broken, nullptr);
  EXPECT_EQ(broken->stages.size(), 1u);  // the stage with the bad blend mode is dropped
  EXPECT_TRUE(has_warning(f, "test.mtr:109:9: unknown blend mode 'sideways'")) << ::testing::PrintToString(f.warnings);
  EXPECT_TRUE(has_warning(f, "test.mtr:112: material textures/test/broken: unknown keyword 'unknownkeyword'"));
}

TEST(MaterialParser, StructuralErrorsThrowWithLine) {
  MaterialTables tables;
  try {
    parse_materials("textures/a\n{\n  diffusemap textures/a\n  /* never closed\n", "bad.mtr", tables);
    FAIL();
  } catch (const ParseError& e) {
    EXPECT_EQ(e.line(), 4);
    EXPECT_NE(std::string(e.what()).find("unterminated /* comment"), std::string::npos);
  }
  try {
    parse_materials("textures/a\n{\n  diffusemap textures/a\n", "open.mtr", tables);
    FAIL();
  } catch (const ParseError& e) {
    EXPECT_EQ(e.line(), 2);
    EXPECT_NE(std::string(e.what()).find("never closed"), std::string::npos);
  }
  try {
    parse_materials("textures/a { { map \"textures/a\n } }", "string.mtr", tables);
    FAIL();
  } catch (const ParseError& e) {
    EXPECT_EQ(e.line(), 1);
    EXPECT_NE(std::string(e.what()).find("unterminated string"), std::string::npos);
  }
}

TEST(MaterialParser, MalformedExpressionsAndProgramsAreWarningsNotCrashes) {
  MaterialTables tables;
  MaterialFile f = parse_materials(
      "a { { map heightmap( , 4 ) } }\n"
      "b { { rgb ( ( ( 1 } }\n"
      "c { { scale 1 } }\n"
      "d { { map addnormals( x, y } }\n"
      "e { { rgb nosuchname } }\n",
      "bad.mtr", tables);
  EXPECT_EQ(f.materials.size(), 5u);
  EXPECT_GE(f.warnings.size(), 5u);
  for (const auto& m : f.materials) EXPECT_TRUE(m.stages.empty()) << m.name;
}

TEST(MaterialParser, VertexColourModesLastKeywordWins) {
  MaterialTables tables;
  MaterialFile f = parse_materials(R"(textures/vc
{
  { blend diffusemap  map textures/a  vertexColor }
  { blend diffusemap  map textures/b  inverseVertexColor }
  { blend diffusemap  map textures/c  inverseVertexColor vertexColor }
  { blend diffusemap  map textures/d }
})", "vc.mtr", tables);
  const MaterialDecl* vc = find(f, "textures/vc");
  ASSERT_NE(vc, nullptr);
  ASSERT_EQ(vc->stages.size(), 4u);
  EXPECT_TRUE(vc->stages[0].vertex_color);
  EXPECT_FALSE(vc->stages[0].inverse_vertex_color);
  EXPECT_FALSE(vc->stages[1].vertex_color);
  EXPECT_TRUE(vc->stages[1].inverse_vertex_color);
  EXPECT_TRUE(vc->stages[2].vertex_color);
  EXPECT_FALSE(vc->stages[2].inverse_vertex_color);
  EXPECT_FALSE(vc->stages[3].vertex_color || vc->stages[3].inverse_vertex_color);
  EXPECT_TRUE(f.warnings.empty()) << ::testing::PrintToString(f.warnings);
}
