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

size_t Scene::world_triangle_count() const {
  size_t n = 0;
  for (int m : area_meshes) n += meshes[m].triangle_count();
  return n;
}

}  // namespace cohort::scene
