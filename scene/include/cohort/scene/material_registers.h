// A material's animated look: the register expressions of the stages that feed Material's colours,
// texture matrix, alphaTest threshold and light stage colour, kept beside the Material (Material::registers)
// when any of them reads time, parms or globals, and evaluated every frame by the commit path.
// Evaluation follows the engine: interaction (diffuse/specular) colours clamped to [0, 1], ambient
// (emissive) colours clamped to [0, 1] by the fixed-function path, light stage RGB below 0.001 snapped
// to 0 and not clamped above; the texture matrix composes each keyword on the right (M = M_prev * M_op).
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "cohort/scene/material_expression.h"

namespace cohort::scene {

struct Material;

// One texture-matrix keyword of a stage, in the order written.
struct TextureOp {
  enum class Kind : uint8_t { Scale, CenterScale, Shear, Translate, Rotate };
  Kind kind = Kind::Translate;
  Expression a, b;   // Rotate: a only (full turns)
};

// st' = (m0 s + m1 t + m2, m3 s + m4 t + m5), the composition of `ops` at these registers.
void compose_texture_matrix(const std::vector<TextureOp>& ops, const RegisterInputs& registers, float (&out)[6]);

struct StageRegisters {
  Expression color[4] = {Expression(1.0f), Expression(1.0f), Expression(1.0f), Expression(1.0f)};
  bool alpha_test = false;
  Expression alpha_ref{0.5f};
  std::vector<TextureOp> tex_ops;
  // texgen wobbleSky: degrees, speed and rotate speed (empty otherwise). The texgen reads time itself,
  // so a wobbling sky depends on time even when the three are constants.
  std::vector<Expression> wobble_sky;
  uint32_t depends() const;
  uint32_t parms_read() const;
};

struct MaterialRegisters {
  std::optional<StageRegisters> diffuse, specular, emissive;  // the stages whose colours the Material holds
  std::optional<StageRegisters> look;    // the stage whose texture matrix and alphaTest the Material holds
  std::optional<StageRegisters> light;   // a light shader's projected stage
  std::optional<StageRegisters> sky;     // a sky's stage: its wobbleSky axes (Material::sky_axis)
  std::optional<StageRegisters> environment;  // an environment stage's colour (Material::environment_color)
  uint32_t depends = 0;                  // kDepends* of all of them
  uint32_t parms_read = 0;               // bit i: parmi is read
};

// `base` with its animated fields evaluated at `registers`; base itself when it has no registers.
void evaluate_material(const Material& base, const RegisterInputs& registers, Material& out);

}  // namespace cohort::scene
