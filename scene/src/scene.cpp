#include "cohort/scene/scene.h"

namespace cohort::scene {

int Scene::find_material(const std::string& wanted) const {
  for (size_t i = 0; i < materials.size(); ++i)
    if (materials[i].name == wanted) return static_cast<int>(i);
  return -1;
}

int Scene::find_mesh(const std::string& wanted) const {
  for (size_t i = 0; i < meshes.size(); ++i)
    if (meshes[i].name == wanted) return static_cast<int>(i);
  return -1;
}

uint32_t pack_rgba8(const glm::vec4& color) {
  uint32_t packed = 0;
  for (int k = 0; k < 4; ++k) {
    const float c = color[k] >= 0.0f ? (color[k] <= 1.0f ? color[k] : 1.0f) : 0.0f;   // NaN -> 0
    packed |= uint32_t(c * 255.0f + 0.5f) << (8 * k);
  }
  return packed;
}

glm::vec4 unpack_rgba8(uint32_t rgba) {
  return glm::vec4(float(rgba & 0xFFu), float((rgba >> 8) & 0xFFu), float((rgba >> 16) & 0xFFu), float(rgba >> 24)) / 255.0f;
}

size_t Scene::world_triangle_count() const {
  size_t n = 0;
  for (int m : area_meshes) n += meshes[m].triangle_count();
  return n;
}

}  // namespace cohort::scene
