// Lights that cannot be rendered: found before conversion, so that no NaN or unbounded volume reaches a
// kernel. Doom 3 maps carry such lights by accident (a zero light_radius, coincident light_right and
// light_up vectors, an origin typed wrong).
#include <cmath>

#include <fmt/format.h>

#include "cohort/core/gpu_scene.h"
#include "cohort/core/light_sampling.h"

namespace cohort::core {
namespace {

// Doom 3 maps span +-65536 units (MAX_WORLD_COORD 128k): an origin far beyond is a typing error.
constexpr float kLargestOrigin = 1.0e6f;

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
std::string text(const glm::vec3& v) { return fmt::format("({} {} {})", v.x, v.y, v.z); }

}  // namespace

std::optional<std::string> light_defect(const scene::Light& light, const scene::Scene& scene,
                                        const GpuSceneOptions& options) {
  if (!finite(light.origin)) return "origin " + text(light.origin) + " is not finite";
  if (std::fabs(light.origin.x) > kLargestOrigin || std::fabs(light.origin.y) > kLargestOrigin ||
      std::fabs(light.origin.z) > kLargestOrigin)
    return fmt::format("origin {} lies beyond +-{} units", text(light.origin), kLargestOrigin);
  if (!finite(light.color)) return "_color " + text(light.color) + " is not finite";
  for (int c = 0; c < 3; ++c)
    if (!finite(light.axis[c])) return "rotation is not finite";
  if (std::fabs(glm::determinant(light.axis)) < 1e-6f) return "rotation is degenerate";
  if (light.type == scene::LightType::Projected) {
    if (!finite(light.target) || !finite(light.right) || !finite(light.up))
      return "light_target/light_right/light_up are not finite";
    if (light.has_start_end && (!finite(light.start) || !finite(light.end)))
      return "light_start/light_end are not finite";
    const float right = glm::length(light.right), up = glm::length(light.up);
    if (!(right > 0.0f) || !(up > 0.0f)) return "light_right or light_up is a zero vector";
    const glm::vec3 normal = glm::cross(light.up, light.right);
    if (!(glm::length(normal) > 1e-6f * right * up)) return "light_right and light_up are parallel";
    if (!(std::fabs(glm::dot(light.target, normal / glm::length(normal))) > 1e-6f))
      return "light_target lies in the plane of light_right and light_up";
  } else {
    if (!finite(light.radius) || !(light.radius.x > 0.0f) || !(light.radius.y > 0.0f) || !(light.radius.z > 0.0f))
      return "light_radius " + text(light.radius) + " is not positive in every axis";
    if (!finite(light.center)) return "light_center " + text(light.center) + " is not finite";
  }
  const KLight k = to_klight(light, scene, options);
  for (float v : k.color)
    if (!std::isfinite(v)) return "colour times the light shader's stage colour is not finite";
  if (!light_bounds(k)) return "its volume is not a closed, finite region (light_start/light_end parallel to the frustum?)";
  return std::nullopt;
}

}  // namespace cohort::core
