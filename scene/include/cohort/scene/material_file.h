// The material (.mtr) reader: material declarations with their stages, as written, before images are
// loaded. Tables are collected for expressions; skins, particles, guides and other decls are skipped.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "cohort/scene/cube_map.h"
#include "cohort/scene/image_program.h"
#include "cohort/scene/material_expression.h"
#include "cohort/scene/material_registers.h"
#include "cohort/scene/parse_error.h"
#include "cohort/scene/scene.h"

namespace cohort::scene {

enum class StageRole : uint8_t { Diffuse, Bump, Specular, Ambient };

// `texgen`: where a stage's texture coordinates come from (explicit: the surface's st).
enum class TexGen : uint8_t { Explicit, Skybox, WobbleSky, Normal, Reflect, Screen };

// How an ambient stage combines with what is behind it.
enum class StageBlend : uint8_t { Replace, Add, Modulate, AlphaBlend, None };

struct MaterialStage {
  StageRole role = StageRole::Ambient;
  StageBlend blend = StageBlend::Replace;
  ImageProgram image;               // empty for stages without one (cube, video, render and shader maps)
  std::string special_map;          // "cubeMap", "videoMap", "program", ... when the stage has no plain image
  CubeMapKind cube_kind = CubeMapKind::None;   // cubeMap / cameraCubeMap (cube_map.h)
  std::string cube_map;             // the faces' common name (before _px / _forward ...)
  TexGen texgen = TexGen::Explicit;
  float wobble_sky[3] = {0, 0, 0};  // texgen wobbleSky: degrees, speed, rotation speed, at time 0 (registers: the expressions)
  // color, alpha_ref and tex_transform: the registers evaluated at time 0 with the world's parms.
  glm::vec4 color{1.0f};
  bool vertex_color = false;           // vertexColor
  bool inverse_vertex_color = false;   // inverseVertexColor
  bool alpha_test = false;
  float alpha_ref = 0.5f;
  float tex_transform[6] = {1, 0, 0, 0, 1, 0};
  StageRegisters registers;   // the expressions behind them
  int line = 0;
};

struct MaterialDecl {
  std::string name;
  std::string file;
  int line = 0;
  std::vector<MaterialStage> stages;
  bool translucent = false, no_shadows = false, two_sided = false, nonsolid = false, no_self_shadow = false;
  bool fog_light = false, blend_light = false, ambient_light = false;
  ImageProgram falloff_image;       // lightFalloffImage
  std::string description;
};

struct MaterialFile {
  std::vector<MaterialDecl> materials;
  std::vector<std::string> warnings;  // "file:line: ..." for approximations and skipped input
};

// Parses one .mtr text. Structural errors (an unterminated comment or string, a block never closed)
// throw ParseError; an error inside one material's body becomes a warning with file:line, and that
// material keeps what was read before it. Tables found are added to `tables` for later expressions.
MaterialFile parse_materials(std::string_view text, const std::string& file_name, MaterialTables& tables);

}  // namespace cohort::scene
