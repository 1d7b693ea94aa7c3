// Per-object conversions from the scene model to the kernel layouts: materials, lights, transforms.
#include <algorithm>
#include <cmath>

#include "cohort/core/gpu_scene.h"

namespace cohort::core {
namespace {

uint32_t to_kblend(scene::BlendClass blend) {
  switch (blend) {
    case scene::BlendClass::Opaque: return K_BLEND_OPAQUE;
    case scene::BlendClass::PassThrough: return K_BLEND_PASSTHROUGH;
    case scene::BlendClass::Additive: return K_BLEND_ADDITIVE;
    case scene::BlendClass::Modulate: return K_BLEND_MODULATE;
    case scene::BlendClass::Alpha: return K_BLEND_ALPHA;
    case scene::BlendClass::Sky: return K_BLEND_SKY;
  }
  return K_BLEND_OPAQUE;
}

void store(float* dst, const glm::vec4& v) { dst[0] = v.x; dst[1] = v.y; dst[2] = v.z; dst[3] = v.w; }
void store(float* dst, const glm::vec3& v) { dst[0] = v.x; dst[1] = v.y; dst[2] = v.z; }

// A plane given in the light's local frame (l = axis^T (p - origin)) moved to world space.
void store_world_plane(float* dst, const glm::vec4& local, const glm::mat3& axis, const glm::vec3& origin) {
  glm::vec3 n = axis * glm::vec3(local);
  store(dst, glm::vec4(n, local.w - glm::dot(n, origin)));
}

// R_SetLightProject (dhewm3 tr_lightrun.cpp) with the origin at zero, in light-local space.
void projected_light_planes(const scene::Light& light, glm::vec4 planes[4]) {
  glm::vec3 right = light.right, up = light.up;
  float r_len = glm::length(right), u_len = glm::length(up);
  right = r_len > 0.0f ? right / r_len : glm::vec3(0, -1, 0);
  up = u_len > 0.0f ? up / u_len : glm::vec3(0, 0, 1);
  if (r_len <= 0.0f) r_len = 1.0f;
  if (u_len <= 0.0f) u_len = 1.0f;
  glm::vec3 normal = glm::normalize(glm::cross(up, right));
  float dist = glm::dot(light.target, normal);
  if (dist < 0.0f) { dist = -dist; normal = -normal; }
  glm::vec4 s(right * (0.5f * dist / r_len), 0.0f);
  glm::vec4 t(up * (-(0.5f * dist) / u_len), 0.0f);
  glm::vec4 q(normal, 0.0f);
  glm::vec4 target(light.target, 1.0f);
  float tq = glm::dot(target, q);
  if (std::fabs(tq) < 1e-6f) tq = 1e-6f;
  s += (0.5f - glm::dot(target, s) / tq) * q;
  t += (0.5f - glm::dot(target, t) / tq) * q;
  glm::vec3 start = light.has_start_end ? light.start : glm::vec3(0.0f);
  glm::vec3 end = light.has_start_end ? light.end : light.target;
  glm::vec3 fall = end - start;
  float len = glm::length(fall);
  if (len <= 0.0f) { fall = normal; len = 1.0f; } else { fall /= len; }
  // F = 0 at start, 1 at end.
  glm::vec4 f(fall / len, -glm::dot(start, fall) / len);
  planes[0] = s; planes[1] = t; planes[2] = q; planes[3] = f;
}

// A point or parallel light's box: its half extents along the light's axes, each at least 1e-3.
glm::vec3 box_light_radius(const scene::Light& light) { return glm::max(light.radius, glm::vec3(1e-3f)); }

void box_light_planes(const scene::Light& light, glm::vec4 planes[4]) {
  const glm::vec3 r = box_light_radius(light);
  planes[0] = glm::vec4(0.5f / r.x, 0.0f, 0.0f, 0.5f);
  planes[1] = glm::vec4(0.0f, 0.5f / r.y, 0.0f, 0.5f);
  planes[2] = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
  planes[3] = glm::vec4(0.0f, 0.0f, 0.5f / r.z, 0.5f);
}

// A cube's faces are consecutive images, so their clamped (light-image) slots are consecutive too: the
// kernel reads face f at the first face's slot + f (sky.h k_cube_sample). K_NONE without six usable faces.
uint32_t cube_slot(int first_face, const scene::Scene& scene) {
  const uint32_t slot = texture_slot(first_face, TextureUse::LightImage, scene);
  for (int face = 1; face < 6 && slot != K_NONE; ++face)
    if (texture_slot(first_face + face, TextureUse::LightImage, scene) != slot + uint32_t(face)) return K_NONE;
  return slot;
}

// A sky whose cube has no six usable faces is its colour alone.
void to_ksky(const scene::Material& material, const scene::Scene& scene, KMaterial& k) {
  k.diffuse_tex = k.normal_tex = k.specular_tex = K_NONE;
  store(k.diffuse_color, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
  store(k.specular_color, glm::vec4(0.0f));
  k.emissive_tex = cube_slot(material.sky_cube_image, scene);
  store(k.tex_transform, material.sky_axis[0]);
  store(k.tex_transform + 3, material.sky_axis[1]);
  k.tex_transform[6] = k.tex_transform[7] = 0.0f;
}

}  // namespace

KMaterial to_kmaterial(const scene::Material& material, const scene::Scene& scene) {
  KMaterial k{};
  store(k.diffuse_color, material.diffuse_color);
  // Doom 3 surfaces without a specular map have no specular at all.
  store(k.specular_color, material.specular_image >= 0 ? material.specular_color : glm::vec4(0.0f));
  store(k.emissive_color, material.emissive_color);
  for (int i = 0; i < 6; ++i) k.tex_transform[i] = material.tex_transform[i];
  k.diffuse_tex = texture_slot(material.diffuse_image, TextureUse::Surface, scene);
  k.normal_tex = texture_slot(material.normal_image, TextureUse::Surface, scene);
  k.specular_tex = texture_slot(material.specular_image, TextureUse::Surface, scene);
  k.emissive_tex = texture_slot(material.emissive_image, TextureUse::Surface, scene);
  const uint32_t blend_diffuse = texture_slot(material.blend_diffuse_image, TextureUse::Surface, scene);
  k.blend_diffuse_tex1 = blend_diffuse != K_NONE && k.diffuse_tex != K_NONE ? blend_diffuse + 1u : 0u;
  k.blend = to_kblend(material.blend);
  k.alpha_ref = material.alpha_ref;
  uint32_t flags = 0;
  if (material.alpha_test) flags |= K_MAT_ALPHA_TEST;
  if (material.translucent) flags |= K_MAT_TRANSLUCENT;
  if (material.no_shadows) flags |= K_MAT_NO_SHADOWS;
  if (material.two_sided) flags |= K_MAT_TWO_SIDED;
  if (material.nonsolid) flags |= K_MAT_NONSOLID;
  if (material.emitter) flags |= K_MAT_EMISSIVE;
  if (material.vertex_color) flags |= K_MAT_VERTEX_COLOR;
  if (material.inverse_vertex_color) flags |= K_MAT_INVERSE_VERTEX_COLOR;
  if (material.no_self_shadow) flags |= K_MAT_NO_SELF_SHADOW;
  // An environment stage whose cube has no six usable faces adds nothing.
  const uint32_t environment = cube_slot(material.environment_cube_image, scene);
  if (environment != K_NONE && k.blend != K_BLEND_SKY && k.blend != K_BLEND_PASSTHROUGH) {
    k.env_tex1 = environment + 1u;
    store(k.env_color, material.environment_color);
    if (material.environment_by_normal) flags |= K_MAT_ENV_BY_NORMAL;
    if (material.environment_under_layer) flags |= K_MAT_ENV_UNDER_LAYER;
  }
  if (k.blend == K_BLEND_SKY) {
    to_ksky(material, scene, k);
    k.flags = flags & ~K_MAT_EMISSIVE;
    return k;
  }
  if (k.blend != K_BLEND_OPAQUE) {
    // A blended layer is its stage image: the kernel reads it as the layer colour, unlit.
    if (k.diffuse_tex == K_NONE && k.emissive_tex != K_NONE) {
      k.diffuse_tex = k.emissive_tex;
      store(k.diffuse_color, glm::vec4(glm::vec3(material.emissive_color), 1.0f));
    }
    k.emissive_tex = K_NONE;
    flags &= ~K_MAT_EMISSIVE;
  }
  k.flags = flags;
  return k;
}

KLight to_klight(const scene::Light& light, const scene::Scene& scene, const GpuSceneOptions& options,
                 const glm::vec3* evaluated_stage_color) {
  KLight k{};
  int material = light.material;
  if (material < 0)
    material = scene.find_material(light.type == scene::LightType::Projected ? "lights/defaultProjectedLight"
                                                                              : "lights/defaultPointLight");
  glm::vec3 stage_color(1.0f);
  k.light_tex = K_NONE;
  k.falloff_tex = K_NONE;
  scene::LightKind kind = scene::LightKind::Normal;
  float stage_alpha = 1.0f;
  bool blend_adds = false;
  if (material >= 0) {
    const scene::Material& m = scene.materials[static_cast<size_t>(material)];
    stage_color = evaluated_stage_color ? *evaluated_stage_color : m.light_stage_color;
    kind = m.light_kind;
    stage_alpha = m.light_stage_alpha;
    blend_adds = m.light_blend_adds;
    k.light_tex = texture_slot(m.light_image, TextureUse::LightImage, scene);
    k.falloff_tex = texture_slot(m.falloff_image, TextureUse::Falloff, scene);
  }
  store(k.origin, light.origin);
  // Fog and blend lights use their stage colour without r_lightScale (RB_FogPass, RB_BlendLight).
  const float scale = kind == scene::LightKind::Fog || kind == scene::LightKind::Blend ? 1.0f : options.light_scale;
  store(k.color, scale * stage_color * light.color);
  store(k.radius, light.radius);
  k.flags = (light.no_shadows ? K_LIGHT_NO_SHADOWS : 0u) | (light.no_specular ? K_LIGHT_NO_SPECULAR : 0u);
  switch (kind) {
    case scene::LightKind::Normal: break;
    case scene::LightKind::Fog:
      k.flags |= K_LIGHT_FOG | K_LIGHT_NO_SHADOWS;
      k.light_tex = K_NONE;   // the fog pass reads neither the light image nor the falloff image
      k.falloff_tex = K_NONE;
      // D = stage alpha when > 1, else 500. The stock fog materials are `colored`, whose alpha is the
      // light's shaderParm3 (the editor's "fog distance"); the parser keeps constant colours only.
      k.fog_distance = stage_alpha > 1.0f ? stage_alpha : light.shader_parms[3] > 1.0f ? light.shader_parms[3] : 500.0f;
      break;
    case scene::LightKind::Blend:
      k.flags |= K_LIGHT_BLEND | K_LIGHT_NO_SHADOWS | (blend_adds ? K_LIGHT_BLEND_ADD : 0u);
      break;
    case scene::LightKind::Ambient:
      k.flags |= K_LIGHT_AMBIENT | K_LIGHT_NO_SHADOWS | K_LIGHT_NO_SPECULAR;
      break;
  }
  for (int row = 0; row < 3; ++row) store(k.axis + 4 * row, glm::vec4(light.axis[row], 0.0f));

  glm::vec4 planes[4] = {glm::vec4(0.0f), glm::vec4(0.0f), glm::vec4(0.0f), glm::vec4(0.0f)};
  switch (light.type) {
    case scene::LightType::Point:
      k.type = K_LIGHT_POINT;
      box_light_planes(light, planes);
      store(k.center, light.origin + light.axis * light.center);
      k.extent = std::clamp(0.1f * std::min({light.radius.x, light.radius.y, light.radius.z}), 1.0f, 32.0f);
      break;
    case scene::LightType::Parallel: {
      k.type = K_LIGHT_PARALLEL;
      box_light_planes(light, planes);
      glm::vec3 dir = light.axis * light.center;
      float len = glm::length(dir);
      store(k.center, len > 0.0f ? dir / len : glm::vec3(0.0f, 0.0f, 1.0f));
      k.extent = 0.02f;
      break;
    }
    case scene::LightType::Projected:
      k.type = K_LIGHT_PROJECTED;
      projected_light_planes(light, planes);
      store(k.center, light.origin);
      k.extent = 4.0f;
      break;
  }
  if (k.type != K_LIGHT_PROJECTED) {
    // The box's farthest corner from its origin, whatever the axis.
    const glm::vec3 r = box_light_radius(light);
    float reach = 0.0f;
    for (int corner = 0; corner < 8; ++corner) {
      const glm::vec3 c((corner & 1) ? r.x : -r.x, (corner & 2) ? r.y : -r.y, (corner & 4) ? r.z : -r.z);
      reach = std::max(reach, glm::length(light.axis * c));
    }
    k.volume_reach = reach;
  }
  store_world_plane(k.plane_s, planes[0], light.axis, light.origin);
  store_world_plane(k.plane_t, planes[1], light.axis, light.origin);
  store_world_plane(k.plane_q, planes[2], light.axis, light.origin);
  store_world_plane(k.plane_f, planes[3], light.axis, light.origin);
  return k;
}

void set_instance_transform(KInstance& instance, const glm::vec3& origin, const glm::mat3& axis) {
  glm::mat3 inv = glm::inverse(axis);
  glm::vec3 inv_t = -(inv * origin);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      instance.object_to_world[4 * r + c] = axis[c][r];
      instance.world_to_object[4 * r + c] = inv[c][r];
    }
    instance.object_to_world[4 * r + 3] = origin[r];
    instance.world_to_object[4 * r + 3] = inv_t[r];
  }
}

}  // namespace cohort::core
