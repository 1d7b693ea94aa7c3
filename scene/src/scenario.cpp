#include "cohort/scene/scenario.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/format.h>
#include <glm/gtc/matrix_transform.hpp>

#include "cohort/scene/md5.h"

namespace cohort::scene {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDoorOpensAt = 0.5, kDoorOpenSeconds = 1.5;
constexpr double kFanDegreesPerSecond = 180.0;
constexpr double kCameraLoopSeconds = 8.0;

glm::mat3 rotation_z(double radians) {
  float c = float(std::cos(radians)), s = float(std::sin(radians));
  return glm::mat3(glm::vec3(c, s, 0), glm::vec3(-s, c, 0), glm::vec3(0, 0, 1));
}

// Smooth start and stop, like a mover's acceleration and deceleration.
double ease(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3.0 - 2.0 * x);
}

float mesh_height(const Scene& scene, int mesh) {
  if (mesh < 0 || size_t(mesh) >= scene.meshes.size() || scene.meshes[mesh].vertices.empty()) return 96.0f;
  float lo = 1e30f, hi = -1e30f;
  for (const Vertex& v : scene.meshes[mesh].vertices) {
    lo = std::min(lo, v.position.z);
    hi = std::max(hi, v.position.z);
  }
  return std::max(hi - lo, 1.0f);
}

}  // namespace

float flicker_factor(double seconds) {
  static const float table[] = {1.0f, 0.9f, 1.0f, 0.35f, 0.8f, 1.0f, 1.0f, 0.2f, 0.6f, 1.0f,
                                0.95f, 0.5f, 1.0f, 0.85f, 0.3f, 1.0f};
  long step = long(std::floor(std::max(seconds, 0.0) * 10.0));
  return table[size_t(step) % std::size(table)];
}

Scenario::Scenario(RenderWorldApi& world, ScenarioOptions options) : world_(world), options_(std::move(options)) {
  door_ = world_.FindEntityDef(options_.door);
  fan_ = world_.FindEntityDef(options_.fan);
  flicker_ = world_.FindLightDef(options_.flicker);
  std::vector<std::string> missing;
  if (door_ < 0) missing.push_back("entity '" + options_.door + "'");
  if (fan_ < 0) missing.push_back("entity '" + options_.fan + "'");
  if (flicker_ < 0) missing.push_back("light '" + options_.flicker + "'");
  if (!missing.empty())
    throw ScenarioError(fmt::format("scene '{}' lacks {} that the scenario drives (the test map in assets/testmap "
                                    "defines them)",
                                    world_.scene().name, fmt::join(missing, ", ")));
  door_closed_ = *world_.EntityDef(door_);
  fan_rest_ = *world_.EntityDef(fan_);
  flicker_base_ = *world_.LightDef(flicker_);
  door_travel_ = mesh_height(world_.scene(), door_closed_.model) - 8.0f;  // func_door's default lip stays visible
  const Scene& scene = world_.scene();
  for (size_t e = 0; e < scene.entities.size(); ++e) {
    const Entity& entity = scene.entities[e];
    if (!entity.anim || entity.mesh < 0 || !scene.meshes[size_t(entity.mesh)].skin) continue;
    const RenderEntity* def = world_.EntityDef(int(e));
    if (def) walkers_.push_back({int(e), *def, entity.anim});
  }
}

std::vector<int> Scenario::walker_handles() const {
  std::vector<int> handles;
  for (const Walker& w : walkers_) handles.push_back(w.handle);
  return handles;
}

RenderEntity Scenario::walker(size_t index, double t) const {
  const Walker& w = walkers_.at(index);
  RenderEntity def = w.start;
  def.joints = anim_pose(*w.anim, int(std::lround(t * 1000.0)));
  // Around a circle to the walker's left, facing along it.
  const double radius = std::max(double(options_.walk_radius), 1.0);
  const double turned = double(options_.walk_speed) * t / radius;
  const glm::vec3 forward = w.start.axis[0], left = w.start.axis[1];
  def.origin = w.start.origin + forward * float(radius * std::sin(turned)) + left * float(radius * (1.0 - std::cos(turned)));
  def.axis = w.start.axis * rotation_z(turned);
  return def;
}

RenderView Scenario::camera(double t) const {
  const Scene& scene = world_.scene();
  double phase = 2.0 * kPi * t / kCameraLoopSeconds;
  double yaw = glm::radians(double(scene.player_yaw)) + glm::radians(30.0) * std::sin(phase);
  glm::vec3 forward_at_start(float(std::cos(glm::radians(double(scene.player_yaw)))),
                             float(std::sin(glm::radians(double(scene.player_yaw)))), 0.0f);
  RenderView view;
  // Walk out along the start direction and back, swaying left and right.
  view.origin = scene.player_start + glm::vec3(0, 0, options_.eye_height) +
                forward_at_start * float(96.0 * (1.0 - std::cos(phase)));
  double pitch = glm::radians(-8.0) * std::sin(2.0 * phase);
  glm::mat3 axis = rotation_z(yaw);
  // Pitch about the camera's left axis: forward tips down, up tips forward.
  glm::vec3 fwd = axis[0] * float(std::cos(pitch)) - axis[2] * float(std::sin(pitch));
  glm::vec3 up = axis[2] * float(std::cos(pitch)) + axis[0] * float(std::sin(pitch));
  view.axis = glm::mat3(fwd, axis[1], up);
  view.fov_x = options_.fov_x;
  view.fov_y = float(glm::degrees(2.0 * std::atan(std::tan(glm::radians(double(options_.fov_x)) / 2.0) /
                                                   double(options_.aspect))));
  view.time_ms = int(std::lround(t * 1000.0));
  return view;
}

void Scenario::frame(int index) {
  const double t = double(index) / options_.frames_per_second;

  RenderEntity door = door_closed_;
  // func_door with movedir -1: straight up in world space, whatever the door's own axis.
  door.origin.z += float(door_travel_ * ease((t - kDoorOpensAt) / kDoorOpenSeconds));
  world_.UpdateEntityDef(door_, door);

  RenderEntity fan = fan_rest_;
  fan.axis = fan_rest_.axis * rotation_z(glm::radians(kFanDegreesPerSecond * t));
  world_.UpdateEntityDef(fan_, fan);

  RenderLight flicker = flicker_base_;
  float f = flicker_factor(t);
  for (int c = kShaderParmRed; c <= kShaderParmBlue; ++c) flicker.shader_parms[c] = flicker_base_.shader_parms[c] * f;
  world_.UpdateLightDef(flicker_, flicker);

  for (size_t w = 0; w < walkers_.size(); ++w) world_.UpdateEntityDef(walkers_[w].handle, walker(w, t));

  RenderView view = camera(t);
  RenderLight flashlight;
  flashlight.point_light = false;
  // Held at the right hip, pointing where the camera looks; a 45-degree cone out to 768 units.
  flashlight.origin = view.origin - view.axis[1] * 8.0f - view.axis[2] * 12.0f;
  flashlight.axis = view.axis;
  flashlight.target = {768, 0, 0};
  flashlight.right = {0, -318, 0};
  flashlight.up = {0, 0, 318};
  flashlight.shader = world_.scene().find_material(options_.flashlight_shader);  // -1: the default projected light
  flashlight.shader_parms[kShaderParmRed] = 1.0f;
  flashlight.shader_parms[kShaderParmGreen] = 0.95f;
  flashlight.shader_parms[kShaderParmBlue] = 0.85f;
  if (flashlight_ < 0 || !world_.LightDef(flashlight_))
    flashlight_ = world_.AddLightDef(flashlight);
  else
    world_.UpdateLightDef(flashlight_, flashlight);

  world_.RenderScene(view);
}

void run_scenario(RenderWorldApi& world, int frames, const ScenarioOptions& options) {
  Scenario scenario(world, options);
  for (int i = 0; i < frames; ++i) {
    scenario.frame(i);
    world.EndFrame();
  }
}

}  // namespace cohort::scene
