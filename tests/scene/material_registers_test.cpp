// Material registers evaluated per frame: expressions and tables against hand-computed values, the
// texture-matrix composition order, and what build_material keeps for the commit path.
#include <gtest/gtest.h>

#include <cmath>

#include "cohort/scene/material_build.h"
#include "cohort/scene/material_file.h"
#include "cohort/scene/material_registers.h"
#include "cohort/scene/parse_error.h"
#include "cohort/scene/vfs.h"

using namespace cohort::scene;

namespace {

MaterialTables test_tables() {
  MaterialTables tables;
  parse_materials("table wave { { 0, 1, 0.5, 0 } }\n"
                  "table steps { snap { 0, 1, 0.5, 0 } }\n"
                  "table ramp { clamp { 0, 2, 4 } }\n"
                  "table one { { 7 } }\n",
                  "tables.mtr", tables);
  return tables;
}

Expression compile(const std::string& text, const MaterialTables& tables) {
  Lexer lex(text, "expr.mtr");
  ExpressionContext context;
  context.tables = &tables;
  Expression e = parse_expression(lex, context);
  EXPECT_TRUE(lex.at_end()) << text;
  return e;
}

float at(const std::string& text, float time, float parm0 = 1.0f, float global1 = 0.0f) {
  static const MaterialTables tables = test_tables();
  RegisterInputs r;
  r.time = time;
  r.parms[0] = parm0;
  r.globals[1] = global1;
  return compile(text, tables).evaluate(r);
}

}  // namespace

TEST(MaterialRegisters, TablesWrapInterpolateSnapAndClamp) {
  // wave: 4 entries over index 0..1, wrapping; i = x * 4.
  EXPECT_FLOAT_EQ(at("wave[ 0.125 ]", 0), 0.5f);    // i = 0.5: halfway 0 -> 1
  EXPECT_FLOAT_EQ(at("wave[ 0.375 ]", 0), 0.75f);   // i = 1.5: halfway 1 -> 0.5
  EXPECT_FLOAT_EQ(at("wave[ 0.875 ]", 0), 0.0f);    // i = 3.5: halfway 0 -> v0 = 0
  EXPECT_FLOAT_EQ(at("wave[ 1.3125 ]", 0), 0.875f); // i = 5.25 wraps to 1.25: 1 + 0.25 * (0.5 - 1)
  EXPECT_FLOAT_EQ(at("wave[ -0.125 ]", 0), 0.0f);   // i = -0.5 wraps to 3.5
  // snap: v(floor i).
  EXPECT_FLOAT_EQ(at("steps[ 0.3 ]", 0), 1.0f);     // i = 1.2
  EXPECT_FLOAT_EQ(at("steps[ 0.6 ]", 0), 0.5f);     // i = 2.4
  // clamp: i = x * (N - 1), held at the ends.
  EXPECT_FLOAT_EQ(at("ramp[ 0.25 ]", 0), 1.0f);     // i = 0.5
  EXPECT_FLOAT_EQ(at("ramp[ 0.75 ]", 0), 3.0f);     // i = 1.5
  EXPECT_FLOAT_EQ(at("ramp[ 2 ]", 0), 4.0f);
  EXPECT_FLOAT_EQ(at("ramp[ -1 ]", 0), 0.0f);
  EXPECT_FLOAT_EQ(at("one[ 0.5 ]", 0), 1.0f);       // the engine: a one-entry table gives 1
}

TEST(MaterialRegisters, ExpressionsFollowTimeParmsAndGlobals) {
  const std::string e = "wave[ time * 0.5 ] * parm0 + global1";
  EXPECT_FLOAT_EQ(at(e, 0.0f, 2.0f, 0.1f), 0.1f);           // wave[0] = 0
  EXPECT_FLOAT_EQ(at(e, 0.25f, 2.0f, 0.1f), 1.1f);          // wave[0.125] = 0.5, x2, +0.1
  EXPECT_FLOAT_EQ(at(e, 0.5f, 3.0f, 0.0f), 3.0f);           // wave[0.25] = 1
  EXPECT_FLOAT_EQ(at(e, 2.25f, 2.0f, 0.0f), 1.0f);          // wave[1.125] wraps to wave[0.125]
  EXPECT_FLOAT_EQ(at("time * 0.1", 12.5f), 1.25f);
  // The engine's grouping: one level's chain binds to the right; * binds tighter than +.
  EXPECT_FLOAT_EQ(at("10 - 4 - 3", 0), 9.0f);
  EXPECT_FLOAT_EQ(at("8 / 2 * 2", 0), 2.0f);
  EXPECT_FLOAT_EQ(at("2 * 3 + 1", 0), 7.0f);
  EXPECT_FLOAT_EQ(at("1 + 2 * 3", 0), 7.0f);
  EXPECT_FLOAT_EQ(at("( time > 1 ) * 5", 2.0f), 5.0f);
  EXPECT_FLOAT_EQ(at("7 % 3", 0), 1.0f);
  // Never NaN or infinity.
  EXPECT_FLOAT_EQ(at("1 / ( time - 1 )", 1.0f), 0.0f);
  EXPECT_FLOAT_EQ(at("time % 0", 3.0f), 0.0f);
  EXPECT_FLOAT_EQ(at("wave[ 1 / 0 ]", 0), 0.0f);
  EXPECT_FLOAT_EQ(at("100000000000000000000000000000000000000 * 1000", 0), 0.0f);
}

TEST(MaterialRegisters, DependenciesAreTracked) {
  const MaterialTables tables = test_tables();
  EXPECT_TRUE(compile("1 + 2 * wave[ 0.3 ]", tables).constant());
  EXPECT_EQ(compile("wave[ time ]", tables).depends(), kDependsTime);
  Expression p = compile("parm4 + parm0", tables);
  EXPECT_EQ(p.depends(), kDependsParms);
  EXPECT_EQ(p.parms_read(), (1u << 4) | 1u);
  EXPECT_EQ(compile("global7", tables).depends(), kDependsGlobals);
}

TEST(MaterialRegisters, BrokenExpressionsNameFileAndLine) {
  const MaterialTables tables = test_tables();
  for (const char* bad : {"nosuchtable[ time ]", "parm12", "global8", "time *", "( time", "frobnicate"}) {
    try {
      compile(bad, tables);
      ADD_FAILURE() << bad << " was accepted";
    } catch (const ParseError& e) {
      EXPECT_NE(std::string(e.what()).find("expr.mtr:1"), std::string::npos) << e.what();
    }
  }
  // In a material: a warning with file:line and the stage dropped, never a crash.
  MaterialTables t2;
  MaterialFile f = parse_materials("textures/x\n{\n  {\n    map _white\n    rgb nosuch[ time ]\n  }\n}\n", "bad.mtr", t2);
  ASSERT_EQ(f.materials.size(), 1u);
  EXPECT_TRUE(f.materials[0].stages.empty());
  ASSERT_FALSE(f.warnings.empty());
  EXPECT_NE(f.warnings[0].find("bad.mtr:5"), std::string::npos) << f.warnings[0];
}

namespace {

const MaterialStage& only_stage(const MaterialFile& f) {
  EXPECT_EQ(f.materials.size(), 1u);
  EXPECT_EQ(f.materials.at(0).stages.size(), 1u);
  return f.materials.at(0).stages.at(0);
}

void expect_matrix(const float (&m)[6], std::initializer_list<float> want) {
  int i = 0;
  for (float w : want) {
    EXPECT_NEAR(m[i], w, 1e-5f) << "m" << i;
    ++i;
  }
}

}  // namespace

// M = M_prev * M_op for each keyword in order: the keyword written last acts on the raw st first.
TEST(MaterialRegisters, TextureMatrixComposesInTheEnginesOrder) {
  MaterialTables tables;
  RegisterInputs r;
  r.time = 1.0f;
  float m[6];
  {
    MaterialFile f = parse_materials("a { { map _white\n scroll time * 0.5, 0\n scale 2, 2 } }", "a.mtr", tables);
    compose_texture_matrix(only_stage(f).registers.tex_ops, r, m);
    expect_matrix(m, {2, 0, 0.5f, 0, 2, 0});   // [1 0 .5; 0 1 0] * [2 0 0; 0 2 0]
  }
  {
    MaterialFile f = parse_materials("b { { map _white\n scale 2, 2\n scroll time * 0.5, 0 } }", "b.mtr", tables);
    compose_texture_matrix(only_stage(f).registers.tex_ops, r, m);
    expect_matrix(m, {2, 0, 1.0f, 0, 2, 0});   // [2 0 0; 0 2 0] * [1 0 .5; 0 1 0]
  }
  {
    // rotate a quarter turn about (0.5, 0.5): c = 0, s = 1.
    MaterialFile f = parse_materials("c { { map _white\n rotate time * 0.25 } }", "c.mtr", tables);
    compose_texture_matrix(only_stage(f).registers.tex_ops, r, m);
    expect_matrix(m, {0, -1, 1, 1, 0, 0});
  }
  {
    // centerScale then shear: [2 0 -.5; 0 3 -1] * [1 .5 -.25; 0 1 0].
    MaterialFile f = parse_materials("d { { map _white\n centerScale 2, 3\n shear 0.5, 0 } }", "d.mtr", tables);
    compose_texture_matrix(only_stage(f).registers.tex_ops, r, m);
    expect_matrix(m, {2, 1, -1.0f, 0, 3, -1});
  }
  {
    // A long scroll loses the integer part of its translation, as the engine draws it.
    RegisterInputs late;
    late.time = 100.25f;
    MaterialFile f = parse_materials("e { { map _white\n scroll time, 0 } }", "e.mtr", tables);
    compose_texture_matrix(only_stage(f).registers.tex_ops, late, m);
    EXPECT_NEAR(m[2], 0.25f, 1e-3f);
  }
}

TEST(MaterialRegisters, BuiltMaterialKeepsOnlyAnimatedRegisters) {
  MaterialTables tables;
  MaterialFile f = parse_materials(
      "table pulse { { 0, 1 } }\n"
      "textures/still { { blend diffusemap\n map _white\n rgb 0.5 } }\n"
      "textures/scroll { { blend diffusemap\n map _white\n scroll time * 0.25, 0 } }\n"
      "textures/glow { { blend add\n map _white\n rgb pulse[ time ] } }\n"
      "textures/tint { { blend diffusemap\n map _white\n colored } }\n"
      "lights/flicker { { map _white\n red pulse[ time + parm4 ]\n green 0.5 } }\n",
      "anim.mtr", tables);
  ASSERT_TRUE(f.warnings.empty()) << f.warnings[0];
  Vfs vfs;
  std::vector<Image> image_store;
  std::vector<std::string> image_warnings;
  ImageLibrary images(vfs, image_store, image_warnings);
  std::map<std::string, Material> built;
  for (const MaterialDecl& d : f.materials) built[d.name] = build_material(d, images, d.name.rfind("lights/", 0) == 0);
  EXPECT_EQ(built["textures/still"].registers, nullptr);
  ASSERT_NE(built["textures/scroll"].registers, nullptr);
  EXPECT_EQ(built["textures/scroll"].registers->depends, kDependsTime);

  Material out;
  RegisterInputs r;
  r.time = 2.0f;
  evaluate_material(built["textures/scroll"], r, out);
  EXPECT_FLOAT_EQ(out.tex_transform[2], 0.5f);
  r.time = 0.25f;   // pulse[0.25]: i = 0.5, halfway 0 -> 1
  evaluate_material(built["textures/glow"], r, out);
  EXPECT_FLOAT_EQ(out.emissive_color.r, 0.5f);
  EXPECT_TRUE(out.emitter);

  const Material& tint = built["textures/tint"];
  ASSERT_NE(tint.registers, nullptr);
  EXPECT_EQ(tint.registers->depends, kDependsParms);
  EXPECT_EQ(tint.registers->parms_read, 0xFu);
  r.parms[0] = 0.25f, r.parms[1] = 0.5f, r.parms[2] = 2.0f;
  evaluate_material(tint, r, out);
  EXPECT_FLOAT_EQ(out.diffuse_color.r, 0.25f);
  EXPECT_FLOAT_EQ(out.diffuse_color.g, 0.5f);
  EXPECT_FLOAT_EQ(out.diffuse_color.b, 1.0f);   // interaction colours clamp to 1

  const Material& flicker = built["lights/flicker"];
  ASSERT_NE(flicker.registers, nullptr);
  RegisterInputs lr;
  lr.time = 0.0f;
  lr.parms[4] = 0.25f;   // the light's phase
  evaluate_material(flicker, lr, out);
  EXPECT_FLOAT_EQ(out.light_stage_color.r, 0.5f);
  EXPECT_FLOAT_EQ(out.light_stage_color.g, 0.5f);
  lr.time = 0.75f;       // pulse[1.0] wraps to pulse[0] = 0, snapped to 0 below 0.001
  evaluate_material(flicker, lr, out);
  EXPECT_FLOAT_EQ(out.light_stage_color.r, 0.0f);
}
