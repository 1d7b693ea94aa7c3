#include "cohort/scene/material_build.h"

#include "ascii_case.h"
#include "cohort/scene/material_registers.h"

namespace cohort::scene {

namespace {

bool draws_image(const MaterialStage& s) { return !s.image.empty() && s.special_map.empty(); }

// Collects the stages whose registers feed the Material; kept only if something in them animates.
struct RegisterSources {
  MaterialRegisters r;
  void set(std::optional<StageRegisters>& slot, const MaterialStage& s) { slot = s.registers; }
  void attach(Material& m) {
    for (auto* slot : {&r.diffuse, &r.specular, &r.emissive, &r.look, &r.light, &r.sky, &r.environment}) {
      if (!*slot) continue;
      if ((*slot)->depends() == 0) {
        slot->reset();
        continue;
      }
      r.depends |= (*slot)->depends();
      r.parms_read |= (*slot)->parms_read();
    }
    if (r.depends != 0) m.registers = std::make_shared<const MaterialRegisters>(std::move(r));
  }
};

void build_light_material(const MaterialDecl& decl, ImageLibrary& images, Material& m, RegisterSources& sources) {
  m.is_light_material = true;
  const std::string context = "light material " + decl.name;
  m.light_kind = decl.fog_light ? LightKind::Fog
               : decl.blend_light ? LightKind::Blend
               : decl.ambient_light ? LightKind::Ambient : LightKind::Normal;
  if (decl.fog_light && !decl.stages.empty()) {
    // The fog pass reads stage 0 only: its colour and, in alpha, the fog distance; not its image.
    m.light_stage_color = glm::vec3(decl.stages.front().color);
    m.light_stage_alpha = decl.stages.front().color.a;
  }
  for (const MaterialStage& s : decl.stages) {
    if (decl.fog_light || !draws_image(s)) continue;
    m.light_image = images.get(s.image, ImageRole::LightProjection, context);
    m.light_stage_color = glm::vec3(s.color);
    sources.set(sources.r.light, s);
    m.light_blend_adds = s.blend == StageBlend::Add;
    break;
  }
  if (!decl.falloff_image.empty()) m.falloff_image = images.get(decl.falloff_image, ImageRole::LightFalloff, context);
  if (decl.fog_light || decl.blend_light) m.blend = BlendClass::PassThrough;
}

void copy_stage_look(const MaterialStage& s, Material& m, RegisterSources& sources) {
  sources.set(sources.r.look, s);
  std::copy(std::begin(s.tex_transform), std::end(s.tex_transform), m.tex_transform);
  if (s.alpha_test) {
    m.alpha_test = true;
    m.alpha_ref = s.alpha_ref;
  }
  // The stage that gives the surface its look decides (one colour mode per material here).
  m.vertex_color = s.vertex_color;
  m.inverse_vertex_color = s.inverse_vertex_color;
}

bool is_sky_stage(const MaterialStage& s) {
  return s.cube_kind != CubeMapKind::None && (s.texgen == TexGen::Skybox || s.texgen == TexGen::WobbleSky) &&
         s.blend != StageBlend::None;
}

// An unlit surface whose stage looks a cube map up by the view direction: what every ray reaching it sees.
void build_sky(const MaterialDecl& decl, const MaterialStage& s, ImageLibrary& images, Material& m,
               RegisterSources& sources) {
  const std::string context = decl.file + ":" + std::to_string(s.line) + ": material " + decl.name;
  m.blend = BlendClass::Sky;
  m.sky_cube_image = images.get_cube(s.cube_map, s.cube_kind, context);
  m.emissive_color = s.color;
  m.diffuse_color = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
  sources.set(sources.r.emissive, s);   // an animated stage colour
  if (s.texgen == TexGen::WobbleSky) {
    m.sky_axis = wobble_sky_axes(s.wobble_sky[0], s.wobble_sky[1], s.wobble_sky[2], 0.0f);
    sources.set(sources.r.sky, s);
  }
}

bool is_environment_stage(const MaterialStage& s) {
  return s.cube_kind != CubeMapKind::None && (s.texgen == TexGen::Reflect || s.texgen == TexGen::Normal);
}

// The first environment stage (glass, chrome): its cube, texgen and colour. The engine draws it with the
// unlit stages, after the interactions and in stage order among the unlit ones (the caller notes one
// written before a layer's filter / blend stage). Only `blend add` stages (gl_one as the destination
// factor, Doom 3's usual choice) are drawn; another blend is a warning and is not drawn. Returns the
// stage drawn, or null.
const MaterialStage* build_environment(const MaterialDecl& decl, ImageLibrary& images, Material& m,
                                       RegisterSources& sources) {
  for (const MaterialStage& s : decl.stages) {
    if (!is_environment_stage(s) || s.blend == StageBlend::None) continue;
    const std::string context = decl.file + ":" + std::to_string(s.line) + ": material " + decl.name;
    if (s.blend != StageBlend::Add) {
      images.warn(context + ": environment cube map stage (texgen " +
                  (s.texgen == TexGen::Reflect ? "reflect" : "normal") +
                  ") with a blend other than add is not drawn");
      continue;
    }
    m.environment_cube_image = images.get_cube(s.cube_map, s.cube_kind, context);
    m.environment_by_normal = s.texgen == TexGen::Normal;
    m.environment_color = glm::vec3(s.color);
    sources.set(sources.r.environment, s);
    return &s;
  }
  return nullptr;
}

void glow_with(Material& m, int image, const MaterialStage& s, RegisterSources& sources) {
  m.emitter = true;
  m.emissive_image = image;
  m.emissive_color = s.color;
  sources.set(sources.r.emissive, s);
}

}  // namespace

static Material build_material_look(const MaterialDecl& decl, ImageLibrary& images, bool as_light, Material& m,
                                    RegisterSources& sources);

Material build_material(const MaterialDecl& decl, ImageLibrary& images, bool as_light) {
  Material m;
  RegisterSources sources;
  Material built = build_material_look(decl, images, as_light, m, sources);
  sources.attach(built);
  return built;
}

static Material build_material_look(const MaterialDecl& decl, ImageLibrary& images, bool as_light, Material& m,
                                    RegisterSources& sources) {
  m.name = decl.name;
  m.source_file = decl.file;
  m.source_line = decl.line;
  m.translucent = decl.translucent;
  m.no_shadows = decl.no_shadows;
  m.two_sided = decl.two_sided;
  m.nonsolid = decl.nonsolid;
  m.no_self_shadow = decl.no_self_shadow;
  const bool light_like = as_light || !decl.falloff_image.empty() || decl.fog_light || decl.blend_light ||
                          decl.ambient_light || starts_with_ignoring_case(decl.name, "lights/");
  if (light_like) {
    build_light_material(decl, images, m, sources);
    if (as_light || m.blend == BlendClass::PassThrough) return m;
  }

  const std::string context = "material " + decl.name;
  bool lit = false, has_specular = false;
  const MaterialStage* first_ambient = nullptr;
  for (const MaterialStage& s : decl.stages) {
    switch (s.role) {
      case StageRole::Diffuse:
        lit = true;
        if (m.diffuse_image >= 0 && m.blend_diffuse_image < 0 && draws_image(s) &&
            (m.vertex_color || m.inverse_vertex_color) && s.vertex_color == m.inverse_vertex_color &&
            s.inverse_vertex_color == m.vertex_color) {
          // The engine draws both interactions, each weighted by its stage's vertex colour mode.
          m.blend_diffuse_image = images.get(s.image, ImageRole::Color, context);
          break;
        }
        if (m.diffuse_image >= 0 || !draws_image(s)) break;
        m.diffuse_image = images.get(s.image, ImageRole::Color, context);
        m.diffuse_color = s.color;
        sources.set(sources.r.diffuse, s);
        copy_stage_look(s, m, sources);
        break;
      case StageRole::Bump:
        lit = true;
        if (m.normal_image < 0 && draws_image(s)) m.normal_image = images.get(s.image, ImageRole::Normal, context);
        break;
      case StageRole::Specular:
        lit = true;
        if (has_specular || !draws_image(s)) break;
        has_specular = true;
        m.specular_image = images.get(s.image, ImageRole::Specular, context);
        m.specular_color = s.color;
        sources.set(sources.r.specular, s);
        break;
      case StageRole::Ambient:
        if (!first_ambient && draws_image(s) && s.blend != StageBlend::None) first_ambient = &s;
        break;
    }
  }
  if (!has_specular) m.specular_color = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);  // the engine's default: no specular

  if (lit) {
    m.blend = BlendClass::Opaque;
    build_environment(decl, images, m, sources);
    // A lit surface with an added or replacing unlit stage glows: Doom 3's light panels and screens.
    for (const MaterialStage& s : decl.stages) {
      if (s.role != StageRole::Ambient || !draws_image(s)) continue;
      if (s.blend == StageBlend::Add || s.blend == StageBlend::Replace) {
        glow_with(m, images.get(s.image, ImageRole::Color, context), s, sources);
        break;
      }
    }
    return m;
  }
  for (const MaterialStage& s : decl.stages) {
    if (!is_sky_stage(s)) continue;
    build_sky(decl, s, images, m, sources);
    return m;
  }
  const MaterialStage* environment = build_environment(decl, images, m, sources);
  if (!first_ambient) {
    if (m.environment_cube_image >= 0) {
      // Glass with nothing but its reflection: a layer that adds the cube and lets the rest through.
      m.blend = BlendClass::Additive;
      m.translucent = true;
      m.diffuse_color = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
      return m;
    }
    m.blend = BlendClass::PassThrough;   // nodraw, caulk, clip, areaportal: nothing drawn
    return m;
  }
  const MaterialStage& s = *first_ambient;
  copy_stage_look(s, m, sources);
  const int image = images.get(s.image, ImageRole::Color, context);
  switch (s.blend) {
    case StageBlend::Add:
    case StageBlend::Replace:
      // Replace is unlit and drawn as is: it shows its image whatever the lighting; Add glows over
      // what is behind it.
      m.blend = s.blend == StageBlend::Add ? BlendClass::Additive : BlendClass::Opaque;
      glow_with(m, image, s, sources);
      m.diffuse_color = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
      if (s.blend == StageBlend::Add) m.translucent = true;
      break;
    case StageBlend::Modulate:
    case StageBlend::AlphaBlend:
      m.blend = s.blend == StageBlend::Modulate ? BlendClass::Modulate : BlendClass::Alpha;
      m.environment_under_layer = environment != nullptr && environment < &s;
      m.diffuse_image = image;
      m.diffuse_color = s.color;
      sources.set(sources.r.diffuse, s);
      m.translucent = true;
      break;
    case StageBlend::None:
      m.blend = BlendClass::PassThrough;
      break;
  }
  return m;
}

Material default_material(const std::string& name, ImageLibrary& images) {
  Material m;
  m.name = name;
  m.is_default = true;
  m.specular_color = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
  ImageProgram program;
  if (images.can_find(name)) {
    program.path = name;
  } else {
    program.path = "_default";
  }
  m.diffuse_image = images.get(program, ImageRole::Color, "material " + name);
  return m;
}

}  // namespace cohort::scene
