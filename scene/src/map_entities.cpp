#include "cohort/scene/map_entities.h"

#include <cmath>
#include <cstdlib>
#include <sstream>

namespace cohort::scene {

namespace {

constexpr float kDegToRad = 3.14159265358979323846f / 180.0f;

glm::vec3 vec3_key(const MapEntity& e, const char* key, glm::vec3 fallback, const std::string& where,
                   std::vector<std::string>& warnings, bool* present = nullptr) {
  auto value = e.get(key);
  if (present) *present = false;
  if (!value) return fallback;
  auto v = parse_floats(*value, 3);
  if (!v) {
    warnings.push_back(where + ": key \"" + key + "\" value \"" + *value + "\" is not three numbers; using the default");
    return fallback;
  }
  if (present) *present = true;
  return {(*v)[0], (*v)[1], (*v)[2]};
}

float float_key(const MapEntity& e, const char* key, float fallback, const std::string& where,
                std::vector<std::string>& warnings) {
  auto value = e.get(key);
  if (!value) return fallback;
  auto v = parse_floats(*value, 1);
  if (!v) {
    warnings.push_back(where + ": key \"" + key + "\" value \"" + *value + "\" is not a number; using the default");
    return fallback;
  }
  return (*v)[0];
}

// The rows of a 3x3 "rotation" value are the axes (forward, left, up); glm stores them as columns.
std::optional<glm::mat3> matrix_key(const MapEntity& e, const char* key, const std::string& where,
                                    std::vector<std::string>& warnings) {
  auto value = e.get(key);
  if (!value) return std::nullopt;
  auto v = parse_floats(*value, 9);
  if (!v) {
    warnings.push_back(where + ": key \"" + key + "\" value is not nine numbers; ignored");
    return std::nullopt;
  }
  glm::mat3 m;
  for (int axis = 0; axis < 3; ++axis)
    m[axis] = glm::vec3((*v)[axis * 3 + 0], (*v)[axis * 3 + 1], (*v)[axis * 3 + 2]);
  for (int axis = 0; axis < 3; ++axis) {
    if (!(glm::length(m[axis]) > 1e-6f)) {
      warnings.push_back(where + ": key \"" + key + "\" has a degenerate axis; using identity");
      return glm::mat3(1.0f);
    }
  }
  return m;
}

glm::mat3 yaw_axis(float degrees) {
  float yaw = std::fmod(degrees, 360.0f) * kDegToRad;
  float c = std::cos(yaw), s = std::sin(yaw);
  glm::mat3 m(1.0f);
  m[0] = {c, s, 0.0f};
  m[1] = {-s, c, 0.0f};
  m[2] = {0.0f, 0.0f, 1.0f};
  return m;
}

}  // namespace

std::optional<std::vector<float>> parse_floats(const std::string& value, size_t n) {
  std::vector<float> out;
  const char* p = value.c_str();
  while (out.size() < n) {
    char* end = nullptr;
    float f = std::strtof(p, &end);
    if (end == p || !std::isfinite(f)) return std::nullopt;
    out.push_back(f);
    p = end;
  }
  while (*p == ' ' || *p == '\t') ++p;
  if (*p != '\0') return std::nullopt;
  return out;
}

bool parse_bool(const std::string& value) { return std::atoi(value.c_str()) != 0; }

bool is_light_entity(const MapEntity& e) { return e.classname() == "light"; }

MapLight light_from_entity(const MapEntity& e, const std::string& where, std::vector<std::string>& warnings) {
  MapLight out;
  Light& light = out.light;
  light.name = e.get_or("name", "");
  light.origin = vec3_key(e, "origin", glm::vec3(0.0f), where, warnings);
  light.center = vec3_key(e, "light_center", glm::vec3(0.0f), where, warnings);

  bool has_target = false, has_up = false, has_right = false, has_start = false, has_end = false;
  glm::vec3 target = vec3_key(e, "light_target", glm::vec3(0.0f), where, warnings, &has_target);
  glm::vec3 up = vec3_key(e, "light_up", glm::vec3(0.0f), where, warnings, &has_up);
  glm::vec3 right = vec3_key(e, "light_right", glm::vec3(0.0f), where, warnings, &has_right);
  if (has_target && has_up && has_right) {
    light.type = LightType::Projected;
    light.target = target;
    light.up = up;
    light.right = right;
    light.start = vec3_key(e, "light_start", glm::vec3(0.0f), where, warnings, &has_start);
    light.end = vec3_key(e, "light_end", target, where, warnings, &has_end);
    light.has_start_end = has_start || has_end;
  } else {
    if (e.get("light_radius")) {
      light.radius = vec3_key(e, "light_radius", glm::vec3(300.0f), where, warnings);
    } else {
      light.radius = glm::vec3(float_key(e, "light", 300.0f, where, warnings));
    }
    light.type = parse_bool(e.get_or("parallel", "0")) ? LightType::Parallel : LightType::Point;
  }

  if (auto m = matrix_key(e, "light_rotation", where, warnings)) {
    light.axis = *m;
  } else if (auto r = matrix_key(e, "rotation", where, warnings)) {
    light.axis = *r;
  } else {
    light.axis = yaw_axis(float_key(e, "angle", 0.0f, where, warnings));
  }

  light.color = vec3_key(e, "_color", glm::vec3(1.0f), where, warnings);
  light.shader_parms[0] = light.color.x;
  light.shader_parms[1] = light.color.y;
  light.shader_parms[2] = light.color.z;
  light.shader_parms[3] = float_key(e, "shaderParm3", 1.0f, where, warnings);
  for (int p = 4; p < 12; ++p) {
    std::string key = "shaderParm" + std::to_string(p);
    light.shader_parms[p] = float_key(e, key.c_str(), 0.0f, where, warnings);
  }
  light.no_shadows = parse_bool(e.get_or("noshadows", "0"));
  light.no_specular = parse_bool(e.get_or("nospecular", "0"));
  out.texture = e.get_or("texture", "");
  return out;
}

Entity entity_from_map(const MapEntity& e, const std::string& where, std::vector<std::string>& warnings) {
  Entity entity;
  entity.classname = e.classname();
  entity.name = e.get_or("name", "");
  entity.origin = vec3_key(e, "origin", glm::vec3(0.0f), where, warnings);
  if (auto m = matrix_key(e, "rotation", where, warnings)) {
    entity.axis = *m;
  } else {
    float angle = float_key(e, "angle", 0.0f, where, warnings);
    entity.axis = angle != 0.0f ? yaw_axis(angle) : glm::mat3(1.0f);
  }
  entity.no_shadows = parse_bool(e.get_or("noshadows", "0"));
  const glm::vec3 color = vec3_key(e, "_color", glm::vec3(1.0f), where, warnings);
  for (int c = 0; c < 3; ++c) entity.shader_parms[c] = color[c];
  entity.shader_parms[3] = float_key(e, "shaderParm3", 1.0f, where, warnings);
  for (int p = 4; p < 12; ++p) {
    const std::string key = "shaderParm" + std::to_string(p);
    entity.shader_parms[p] = float_key(e, key.c_str(), 0.0f, where, warnings);
  }
  for (const auto& [key, value] : e.keys) entity.keys[key] = value;
  return entity;
}

}  // namespace cohort::scene
