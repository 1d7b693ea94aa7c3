// Scene deltas in the shape of idTech 4's idRenderWorld: the game adds, updates and frees entity and
// light definitions by stable integer handles, defines materials, textures and models, and renders a
// view each frame. RenderWorld keeps the current state and a per-frame change log, which the core's
// world sync (core/world_sync.h) turns into commit records for the tracers.
//
// Handles behave like the engine's: Add*Def returns the lowest free handle, Free*Def makes it free
// again. A RenderWorld seeded from a loaded Scene gives map entity i entity handle i and map light i
// light handle i, so handles match the compiled scene's KInstance::entity and light order. The static
// world (the area meshes) is not an entity def: it never moves.
#pragma once

#include <cstdint>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "cohort/scene/scene.h"

namespace cohort::scene {

constexpr int kMaxEntityShaderParms = 12;
// Shader parm slots, as the engine names them.
constexpr int kShaderParmRed = 0, kShaderParmGreen = 1, kShaderParmBlue = 2, kShaderParmAlpha = 3,
              kShaderParmTimeOffset = 4;

struct RenderEntity {
  int model = -1;              // Scene::meshes index; -1 with model_name empty: no geometry
  std::string model_name;      // when set, wins over `model` (the engine refers to models by name)
  glm::vec3 origin{0.0f};
  glm::mat3 axis{1.0f};        // columns: the entity's x (forward), y (left), z (up) in world space
  float shader_parms[kMaxEntityShaderParms] = {1, 1, 1, 1, 0, 0, 0, 0, 0, 0, 0, 0};
  int custom_shader = -1;      // material that replaces every surface's own; -1: none
  bool no_shadows = false;
  bool no_self_shadow = false;
  int suppress_surface_in_view_id = 0;  // not drawn in the view with this id (0: none)
  int allow_surface_in_view_id = 0;     // drawn only in the view with this id (0: every view)
  // The skeleton's pose in model space, one per joint of the model's skin (the engine's renderEntity
  // joints): a skinned model is drawn in this pose. Empty: the model as loaded (an MD5 in bind pose).
  // A count other than the skin's joint count is not drawn, as in the engine.
  std::vector<JointTransform> joints;
  bool operator==(const RenderEntity&) const = default;
};

struct RenderLight {
  glm::vec3 origin{0.0f};
  glm::mat3 axis{1.0f};        // columns: the light's x, y, z axes in world space
  bool point_light = true;     // point: radius/center; otherwise projected (or parallel)
  bool parallel = false;       // a point light whose center is the direction toward the light
  glm::vec3 radius{300.0f};
  glm::vec3 center{0.0f};
  // Projected lights, relative to origin, in the light's axis frame.
  glm::vec3 target{0.0f}, right{0.0f}, up{0.0f}, start{0.0f}, end{0.0f};
  bool has_start_end = false;
  int shader = -1;             // Scene::materials index of the light shader; -1: the default for its type
  std::string shader_name;     // when set, wins over `shader`
  float shader_parms[kMaxEntityShaderParms] = {1, 1, 1, 1, 0, 0, 0, 0, 0, 0, 0, 0};  // 0-2: colour
  bool no_shadows = false, no_specular = false;
  bool operator==(const RenderLight&) const = default;
};

struct RenderView {
  glm::vec3 origin{0.0f};
  glm::mat3 axis{1.0f};        // columns: forward (the view looks down +X), left, up
  float fov_x = 90.0f, fov_y = 73.74f;  // degrees
  int time_ms = 0;
  int view_id = 0;
  bool operator==(const RenderView&) const = default;
};

// What changed since the last TakeChanges(): handles whose definition was added, updated or freed.
// A handle freed and re-added in one frame is in both sets; the current state says which won.
struct ChangeLog {
  std::set<int> entities, freed_entities;
  std::set<int> lights, freed_lights;
  std::set<int> materials, textures, models;  // Scene::materials / images / meshes indices
  bool view = false;
  int frames_ended = 0;
  bool empty() const {
    return entities.empty() && freed_entities.empty() && lights.empty() && freed_lights.empty() &&
           materials.empty() && textures.empty() && models.empty() && !view;
  }
};

// A call that does not fit the world's state: an unknown handle, a model or shader name that the scene
// lacks, a handle that is out of range.
class RenderWorldError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The calls a game makes. RenderWorld implements them; the stream Recorder wraps a RenderWorld and
// writes each call down; the scenario generator drives either.
class RenderWorldApi {
 public:
  virtual ~RenderWorldApi() = default;
  virtual int AddEntityDef(const RenderEntity& entity) = 0;
  virtual void UpdateEntityDef(int handle, const RenderEntity& entity) = 0;
  virtual void FreeEntityDef(int handle) = 0;
  virtual int AddLightDef(const RenderLight& light) = 0;
  virtual void UpdateLightDef(int handle, const RenderLight& light) = 0;
  virtual void FreeLightDef(int handle) = 0;
  // Define or redefine by name; returns the Scene::materials / images / meshes index.
  virtual int DefineMaterial(const Material& material) = 0;
  virtual int DefineTexture(const Image& image) = 0;
  virtual int DefineModel(const Mesh& mesh) = 0;
  virtual void RenderScene(const RenderView& view) = 0;
  // Closes the frame (the engine's end-of-frame in its demo stream).
  virtual void EndFrame() = 0;

  // Read-only queries a game needs to find its defs.
  virtual const RenderEntity* EntityDef(int handle) const = 0;
  virtual const RenderLight* LightDef(int handle) const = 0;
  virtual int FindEntityDef(const std::string& name) const = 0;  // -1 if no seeded entity has the name
  virtual int FindLightDef(const std::string& name) const = 0;
  virtual const Scene& scene() const = 0;
};

class RenderWorld : public RenderWorldApi {
 public:
  RenderWorld() = default;
  // Seed from a loaded map: every map entity and light gets a handle (entity i -> handle i), the
  // materials, images and meshes are the scene's. The seed is not in the change log.
  explicit RenderWorld(Scene scene);

  int AddEntityDef(const RenderEntity& entity) override;
  void UpdateEntityDef(int handle, const RenderEntity& entity) override;
  void FreeEntityDef(int handle) override;
  int AddLightDef(const RenderLight& light) override;
  void UpdateLightDef(int handle, const RenderLight& light) override;
  void FreeLightDef(int handle) override;
  int DefineMaterial(const Material& material) override;
  int DefineTexture(const Image& image) override;
  int DefineModel(const Mesh& mesh) override;
  void RenderScene(const RenderView& view) override;
  void EndFrame() override;

  const RenderEntity* EntityDef(int handle) const override;
  const RenderLight* LightDef(int handle) const override;
  int FindEntityDef(const std::string& name) const override;
  int FindLightDef(const std::string& name) const override;
  const Scene& scene() const override { return scene_; }

  // Slots up to the highest handle ever used; empty optionals are free handles.
  const std::vector<std::optional<RenderEntity>>& entity_defs() const { return entities_; }
  const std::vector<std::optional<RenderLight>>& light_defs() const { return lights_; }
  const std::optional<RenderView>& view() const { return view_; }
  int frame_count() const { return frames_ended_; }

  // The change log since the last call, which it clears.
  ChangeLog TakeChanges();
  const ChangeLog& changes() const { return changes_; }

  // A light def as the scene model's Light, for the conversions that take one (core::to_klight).
  Light scene_light(int handle) const;

 private:
  RenderEntity resolved(const RenderEntity& entity) const;
  RenderLight resolved(const RenderLight& light) const;

  Scene scene_;
  std::vector<std::optional<RenderEntity>> entities_;
  std::vector<std::optional<RenderLight>> lights_;
  std::vector<std::string> entity_names_, light_names_;  // of the seeded defs
  std::optional<RenderView> view_;
  ChangeLog changes_;
  int frames_ended_ = 0;
};

// Conversions between the scene model and the defs.
RenderEntity render_entity_from(const Entity& entity);
RenderLight render_light_from(const Light& light);

// Largest definitions RenderWorld accepts (so a corrupt stream cannot ask for unbounded memory).
constexpr int kMaxHandles = 1 << 20;
constexpr size_t kMaxEntityJoints = 4096;

}  // namespace cohort::scene
