#include "cohort/scene/render_world.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace cohort::scene {
namespace {

// Entity and light defs keep the same handle bookkeeping. DefKind says which change-log sets a kind
// marks and how the calls name it in errors (AddEntityDef, FreeLightDef, ...).
template <class Def>
struct DefKind;
template <>
struct DefKind<RenderEntity> {
  static constexpr const char* name = "Entity";
  static constexpr auto changed = &ChangeLog::entities, freed = &ChangeLog::freed_entities;
};
template <>
struct DefKind<RenderLight> {
  static constexpr const char* name = "Light";
  static constexpr auto changed = &ChangeLog::lights, freed = &ChangeLog::freed_lights;
};

template <class Def>
int lowest_free(std::vector<std::optional<Def>>& slots) {
  auto it = std::find_if(slots.begin(), slots.end(), [](const auto& s) { return !s.has_value(); });
  if (it != slots.end()) return static_cast<int>(it - slots.begin());
  if (slots.size() >= size_t(kMaxHandles))
    throw RenderWorldError(fmt::format("Add{}Def: all {} handles are in use", DefKind<Def>::name, kMaxHandles));
  slots.emplace_back();
  return static_cast<int>(slots.size() - 1);
}

template <class Def>
const Def* live_or_null(const std::vector<std::optional<Def>>& slots, int handle) {
  if (handle < 0 || size_t(handle) >= slots.size() || !slots[handle]) return nullptr;
  return &*slots[handle];
}

template <class Def>
std::optional<Def>& live(std::vector<std::optional<Def>>& slots, int handle, const char* call) {
  if (!live_or_null(slots, handle))
    throw RenderWorldError(fmt::format("{}{}Def: handle {} is not a live def", call, DefKind<Def>::name, handle));
  return slots[handle];
}

template <class Def>
int add_def(std::vector<std::optional<Def>>& slots, Def def, ChangeLog& changes) {
  int handle = lowest_free(slots);
  slots[handle] = std::move(def);
  (changes.*DefKind<Def>::changed).insert(handle);
  return handle;
}

template <class Def>
void update_def(std::vector<std::optional<Def>>& slots, int handle, Def def, ChangeLog& changes) {
  live(slots, handle, "Update") = std::move(def);
  (changes.*DefKind<Def>::changed).insert(handle);
}

// A freed handle loses its seeded name too, so Find*Def cannot return a later def that reuses it.
template <class Def>
void free_def(std::vector<std::optional<Def>>& slots, std::vector<std::string>& seeded_names, int handle,
              ChangeLog& changes) {
  live(slots, handle, "Free").reset();
  if (size_t(handle) < seeded_names.size()) seeded_names[handle].clear();
  (changes.*DefKind<Def>::changed).erase(handle);
  (changes.*DefKind<Def>::freed).insert(handle);
}

template <class Def>
int find_seeded(const std::vector<std::optional<Def>>& slots, const std::vector<std::string>& seeded_names,
                const std::string& name) {
  for (size_t i = 0; i < seeded_names.size(); ++i)
    if (seeded_names[i] == name && slots[i]) return int(i);
  return -1;
}

// DefineMaterial, DefineTexture and DefineModel replace the one at `found` (the index of the one with
// the same name, -1 if none) or add a new one at the end, and mark its index changed.
template <class T>
int define_by_name(std::vector<T>& items, int found, const T& item, std::set<int>& changed, const char* too_many) {
  int index = found;
  if (index < 0) {
    if (items.size() >= size_t(kMaxHandles)) throw RenderWorldError(too_many);
    index = int(items.size());
    items.push_back(item);
  } else {
    items[index] = item;
  }
  changed.insert(index);
  return index;
}

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
bool finite(const glm::mat3& m) { return finite(m[0]) && finite(m[1]) && finite(m[2]); }

// A light as the scene model's Light and as a RenderLight: the same values, but for its type and colour,
// which the def keeps as the engine does (point/parallel flags, shader parms 0-2). Both conversions
// walk this one list of the shared fields, `copy` moving each one way or the other.
template <class SceneLight, class DefLight, class Copy>
void for_each_shared_light_field(SceneLight& light, DefLight& def, Copy copy) {
  copy(light.origin, def.origin);
  copy(light.axis, def.axis);
  copy(light.radius, def.radius);
  copy(light.center, def.center);
  copy(light.target, def.target);
  copy(light.right, def.right);
  copy(light.up, def.up);
  copy(light.start, def.start);
  copy(light.end, def.end);
  copy(light.has_start_end, def.has_start_end);
  copy(light.material, def.shader);
  copy(light.no_shadows, def.no_shadows);
  copy(light.no_specular, def.no_specular);
}

}  // namespace

RenderEntity render_entity_from(const Entity& entity) {
  RenderEntity def;
  def.model = entity.mesh;
  def.origin = entity.origin;
  def.axis = entity.axis;
  def.no_shadows = entity.no_shadows;
  std::copy(std::begin(entity.shader_parms), std::end(entity.shader_parms), def.shader_parms);
  return def;
}

RenderLight render_light_from(const Light& light) {
  RenderLight def;
  for_each_shared_light_field(light, def, [](const auto& from, auto& to) { to = from; });
  def.point_light = light.type != LightType::Projected;
  def.parallel = light.type == LightType::Parallel;
  std::copy(std::begin(light.shader_parms), std::end(light.shader_parms), def.shader_parms);
  // _color is what the engine puts in shader parms 0-2.
  def.shader_parms[kShaderParmRed] = light.color.r;
  def.shader_parms[kShaderParmGreen] = light.color.g;
  def.shader_parms[kShaderParmBlue] = light.color.b;
  return def;
}

RenderWorld::RenderWorld(Scene scene) : scene_(std::move(scene)) {
  for (const Entity& e : scene_.entities) {
    entities_.emplace_back(render_entity_from(e));
    entity_names_.push_back(e.name);
  }
  for (const Light& l : scene_.lights) {
    lights_.emplace_back(render_light_from(l));
    light_names_.push_back(l.name);
  }
}

RenderEntity RenderWorld::resolved(const RenderEntity& entity) const {
  RenderEntity def = entity;
  if (!def.model_name.empty()) {
    def.model = scene_.find_mesh(def.model_name);
    if (def.model < 0) throw RenderWorldError(fmt::format("entity def: no model named '{}'", def.model_name));
  } else if (def.model < -1 || def.model >= int(scene_.meshes.size())) {
    throw RenderWorldError(fmt::format("entity def: model {} out of range (the scene has {} meshes)", def.model,
                                       scene_.meshes.size()));
  }
  if (def.custom_shader < -1 || def.custom_shader >= int(scene_.materials.size()))
    throw RenderWorldError(fmt::format("entity def: custom shader {} out of range ({} materials)", def.custom_shader,
                                       scene_.materials.size()));
  if (!finite(def.origin) || !finite(def.axis)) throw RenderWorldError("entity def: origin or axis is not finite");
  if (def.joints.size() > kMaxEntityJoints)
    throw RenderWorldError(fmt::format("entity def: {} joints (at most {})", def.joints.size(), kMaxEntityJoints));
  for (const JointTransform& j : def.joints)
    if (!finite(j.position) || !std::isfinite(j.rotation.x + j.rotation.y + j.rotation.z + j.rotation.w))
      throw RenderWorldError("entity def: a joint is not finite");
  def.model_name.clear();  // the state holds the resolved index only
  return def;
}

RenderLight RenderWorld::resolved(const RenderLight& light) const {
  RenderLight def = light;
  if (!def.shader_name.empty()) {
    def.shader = scene_.find_material(def.shader_name);
    if (def.shader < 0) throw RenderWorldError(fmt::format("light def: no light shader named '{}'", def.shader_name));
  } else if (def.shader < -1 || def.shader >= int(scene_.materials.size())) {
    throw RenderWorldError(fmt::format("light def: shader {} out of range ({} materials)", def.shader,
                                       scene_.materials.size()));
  }
  if (!finite(def.origin) || !finite(def.axis) || !finite(def.radius) || !finite(def.center) ||
      !finite(def.target) || !finite(def.right) || !finite(def.up) || !finite(def.start) || !finite(def.end))
    throw RenderWorldError("light def: a vector is not finite");
  def.shader_name.clear();
  return def;
}

int RenderWorld::AddEntityDef(const RenderEntity& entity) { return add_def(entities_, resolved(entity), changes_); }
void RenderWorld::UpdateEntityDef(int handle, const RenderEntity& entity) {
  update_def(entities_, handle, resolved(entity), changes_);
}
void RenderWorld::FreeEntityDef(int handle) { free_def(entities_, entity_names_, handle, changes_); }

int RenderWorld::AddLightDef(const RenderLight& light) { return add_def(lights_, resolved(light), changes_); }
void RenderWorld::UpdateLightDef(int handle, const RenderLight& light) {
  update_def(lights_, handle, resolved(light), changes_);
}
void RenderWorld::FreeLightDef(int handle) { free_def(lights_, light_names_, handle, changes_); }

int RenderWorld::DefineMaterial(const Material& material) {
  auto image_ok = [&](int i) { return i >= -1 && i < int(scene_.images.size()); };
  for (int i : {material.diffuse_image, material.normal_image, material.specular_image, material.emissive_image,
                material.light_image, material.falloff_image, material.blend_diffuse_image})
    if (!image_ok(i))
      throw RenderWorldError(fmt::format("DefineMaterial '{}': image {} out of range ({} images)", material.name, i,
                                         scene_.images.size()));
  if (material.sky_cube_image != -1 && !(material.sky_cube_image >= 0 && material.sky_cube_image + 5 < int(scene_.images.size())))
    throw RenderWorldError(fmt::format("DefineMaterial '{}': sky cube faces {}..{} out of range ({} images)", material.name,
                                       material.sky_cube_image, material.sky_cube_image + 5, scene_.images.size()));
  if (material.environment_cube_image != -1 &&
      !(material.environment_cube_image >= 0 && material.environment_cube_image + 5 < int(scene_.images.size())))
    throw RenderWorldError(fmt::format("DefineMaterial '{}': environment cube faces {}..{} out of range ({} images)",
                                       material.name, material.environment_cube_image,
                                       material.environment_cube_image + 5, scene_.images.size()));
  return define_by_name(scene_.materials, scene_.find_material(material.name), material, changes_.materials,
                        "DefineMaterial: too many materials");
}

int RenderWorld::DefineTexture(const Image& image) {
  if (image.width <= 0 || image.height <= 0 ||
      image.rgba.size() != size_t(image.width) * size_t(image.height) * 4)
    throw RenderWorldError(fmt::format("DefineTexture '{}': {}x{} needs {} bytes of RGBA, got {}", image.name,
                                       image.width, image.height, size_t(std::max(image.width, 0)) *
                                       size_t(std::max(image.height, 0)) * 4, image.rgba.size()));
  auto it = std::find_if(scene_.images.begin(), scene_.images.end(),
                         [&](const Image& i) { return i.name == image.name; });
  const int found = it == scene_.images.end() ? -1 : int(it - scene_.images.begin());
  return define_by_name(scene_.images, found, image, changes_.textures, "DefineTexture: too many textures");
}

int RenderWorld::DefineModel(const Mesh& mesh) {
  if (mesh.indices.size() % 3 != 0)
    throw RenderWorldError(fmt::format("DefineModel '{}': {} indices is not whole triangles", mesh.name,
                                       mesh.indices.size()));
  for (uint32_t i : mesh.indices)
    if (i >= mesh.vertices.size())
      throw RenderWorldError(fmt::format("DefineModel '{}': index {} past its {} vertices", mesh.name, i,
                                         mesh.vertices.size()));
  if (!mesh.colors.empty() && mesh.colors.size() != mesh.vertices.size())
    throw RenderWorldError(fmt::format("DefineModel '{}': {} vertex colours for {} vertices", mesh.name,
                                       mesh.colors.size(), mesh.vertices.size()));
  for (const Surface& s : mesh.surfaces) {
    if (s.material < -1 || s.material >= int(scene_.materials.size()))
      throw RenderWorldError(fmt::format("DefineModel '{}': surface material {} out of range", mesh.name, s.material));
    if (size_t(s.first_index) + s.index_count > mesh.indices.size())
      throw RenderWorldError(fmt::format("DefineModel '{}': a surface runs past the index list", mesh.name));
  }
  return define_by_name(scene_.meshes, scene_.find_mesh(mesh.name), mesh, changes_.models,
                        "DefineModel: too many models");
}

void RenderWorld::RenderScene(const RenderView& view) {
  if (!finite(view.origin) || !finite(view.axis) || !(view.fov_x > 0.0f && view.fov_x < 180.0f) ||
      !(view.fov_y > 0.0f && view.fov_y < 180.0f))
    throw RenderWorldError(fmt::format("RenderScene: bad view (fov {} x {}, or a non-finite origin/axis)", view.fov_x,
                                       view.fov_y));
  view_ = view;
  changes_.view = true;
}

void RenderWorld::EndFrame() {
  ++frames_ended_;
  ++changes_.frames_ended;
}

const RenderEntity* RenderWorld::EntityDef(int handle) const { return live_or_null(entities_, handle); }

const RenderLight* RenderWorld::LightDef(int handle) const { return live_or_null(lights_, handle); }

int RenderWorld::FindEntityDef(const std::string& name) const { return find_seeded(entities_, entity_names_, name); }

int RenderWorld::FindLightDef(const std::string& name) const { return find_seeded(lights_, light_names_, name); }

ChangeLog RenderWorld::TakeChanges() {
  ChangeLog taken = std::move(changes_);
  changes_ = {};
  return taken;
}

Light RenderWorld::scene_light(int handle) const {
  const RenderLight* def = LightDef(handle);
  if (!def) throw RenderWorldError(fmt::format("scene_light: handle {} is not a live light def", handle));
  Light light;
  if (size_t(handle) < light_names_.size()) light.name = light_names_[handle];
  for_each_shared_light_field(light, *def, [](auto& to, const auto& from) { to = from; });
  light.type = def->parallel ? LightType::Parallel : def->point_light ? LightType::Point : LightType::Projected;
  light.color = {def->shader_parms[kShaderParmRed], def->shader_parms[kShaderParmGreen],
                 def->shader_parms[kShaderParmBlue]};
  std::copy(std::begin(def->shader_parms), std::end(def->shader_parms), light.shader_parms);
  return light;
}

}  // namespace cohort::scene
