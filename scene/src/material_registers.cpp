#include "cohort/scene/material_registers.h"

#include <algorithm>
#include <cmath>

#include "cohort/scene/cube_map.h"
#include "cohort/scene/scene.h"

namespace cohort::scene {

namespace {

// m = m * reg: the engine multiplies each new keyword's matrix on the right (MultiplyTextureMatrix).
void multiply(float (&m)[6], const float (&reg)[6]) {
  float r[6];
  r[0] = m[0] * reg[0] + m[1] * reg[3];
  r[1] = m[0] * reg[1] + m[1] * reg[4];
  r[2] = m[0] * reg[2] + m[1] * reg[5] + m[2];
  r[3] = m[3] * reg[0] + m[4] * reg[3];
  r[4] = m[3] * reg[1] + m[4] * reg[4];
  r[5] = m[3] * reg[2] + m[4] * reg[5] + m[5];
  std::copy(r, r + 6, m);
}

glm::vec4 evaluate_color(const StageRegisters& s, const RegisterInputs& r) {
  return glm::vec4(s.color[0].evaluate(r), s.color[1].evaluate(r), s.color[2].evaluate(r), s.color[3].evaluate(r));
}

}  // namespace

void compose_texture_matrix(const std::vector<TextureOp>& ops, const RegisterInputs& registers, float (&out)[6]) {
  const float identity[6] = {1, 0, 0, 0, 1, 0};
  std::copy(identity, identity + 6, out);
  for (const TextureOp& op : ops) {
    const float a = op.a.evaluate(registers);
    const float b = op.kind == TextureOp::Kind::Rotate ? 0.0f : op.b.evaluate(registers);
    switch (op.kind) {
      case TextureOp::Kind::Scale: multiply(out, {a, 0, 0, 0, b, 0}); break;
      case TextureOp::Kind::CenterScale: multiply(out, {a, 0, 0.5f - 0.5f * a, 0, b, 0.5f - 0.5f * b}); break;
      case TextureOp::Kind::Shear: multiply(out, {1, a, -0.5f * a, b, 1, -0.5f * b}); break;
      case TextureOp::Kind::Translate: multiply(out, {1, 0, a, 0, 1, b}); break;
      case TextureOp::Kind::Rotate: {
        // Turns; the engine reads sinTable/cosTable, one period over 0..1, which this matches.
        const float angle = std::fmod(a, 1.0f) * 6.28318530718f;
        const float c = std::cos(angle), s = std::sin(angle);
        multiply(out, {c, -s, 0.5f - 0.5f * c + 0.5f * s, s, c, 0.5f - 0.5f * s - 0.5f * c});
        break;
      }
    }
  }
  // The engine drops the integer part of a large translation (RB_GetShaderTextureMatrix) so that a long
  // scroll keeps its precision; with a repeating texture the image is the same.
  for (int i : {2, 5})
    if (std::fabs(out[i]) > 40.0f) out[i] -= float(int(out[i]));
}

uint32_t StageRegisters::depends() const {
  uint32_t d = alpha_test ? alpha_ref.depends() : 0u;
  for (const Expression& e : color) d |= e.depends();
  for (const TextureOp& op : tex_ops) d |= op.a.depends() | op.b.depends();
  for (const Expression& e : wobble_sky) d |= e.depends() | kDependsTime;
  return d;
}

uint32_t StageRegisters::parms_read() const {
  uint32_t p = alpha_test ? alpha_ref.parms_read() : 0u;
  for (const Expression& e : color) p |= e.parms_read();
  for (const TextureOp& op : tex_ops) p |= op.a.parms_read() | op.b.parms_read();
  for (const Expression& e : wobble_sky) p |= e.parms_read();
  return p;
}

void evaluate_material(const Material& base, const RegisterInputs& r, Material& out) {
  out = base;
  if (!base.registers) return;
  const MaterialRegisters& g = *base.registers;
  const glm::vec4 zero(0.0f), one(1.0f);
  if (g.diffuse) out.diffuse_color = glm::clamp(evaluate_color(*g.diffuse, r), zero, one);
  if (g.specular && base.specular_image >= 0) out.specular_color = glm::clamp(evaluate_color(*g.specular, r), zero, one);
  if (g.emissive) out.emissive_color = glm::clamp(evaluate_color(*g.emissive, r), zero, one);
  if (g.look) {
    compose_texture_matrix(g.look->tex_ops, r, out.tex_transform);
    if (g.look->alpha_test) out.alpha_ref = g.look->alpha_ref.evaluate(r);
  }
  if (g.environment) out.environment_color = glm::clamp(glm::vec3(evaluate_color(*g.environment, r)), glm::vec3(zero), glm::vec3(one));
  if (g.sky && g.sky->wobble_sky.size() == 3)
    out.sky_axis = wobble_sky_axes(g.sky->wobble_sky[0].evaluate(r), g.sky->wobble_sky[1].evaluate(r),
                                   g.sky->wobble_sky[2].evaluate(r), r.time);
  if (g.light) {
    glm::vec3 c = glm::vec3(evaluate_color(*g.light, r));
    for (int i = 0; i < 3; ++i) c[i] = c[i] < 0.001f ? 0.0f : c[i];
    out.light_stage_color = c;
  }
}

}  // namespace cohort::scene
