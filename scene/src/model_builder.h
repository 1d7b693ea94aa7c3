// Turns the corners of a model file's triangles into a Mesh the way the engine's model conversion does:
// identical corners weld within a group (an ASE object, an LWO layer), triangles merge into one surface
// per material in order of first use, missing normals are generated (sum of unit face normals over
// every corner at the same position) and tangents derived. Private to the scene library.
#pragma once

#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "cohort/scene/model_file.h"

namespace cohort::scene {

struct ModelCorner {
  glm::vec3 position{0.0f};
  glm::vec2 st{0.0f};
  glm::vec3 normal{0.0f};
  bool has_normal = false;        // false: generated from the faces
  glm::vec4 color{1.0f};
};

class ModelBuilder {
 public:
  explicit ModelBuilder(std::string name) : name_(std::move(name)) {}
  // Corners weld only with corners of the same group.
  void begin_group() { ++group_; }
  // One triangle, corners in idTech order (clockwise seen from the front).
  void add_triangle(const std::string& material, const ModelCorner (&corners)[3]);
  size_t triangle_count() const { return triangle_count_; }
  ModelFile finish(bool keep_colors);

 private:
  using Key = std::tuple<int, float, float, float, float, float, float, float, float, bool, float, float, float, float>;
  struct Bucket {
    std::vector<uint32_t> indices;
  };
  std::string name_;
  int group_ = 0;
  size_t triangle_count_ = 0;
  std::vector<ModelCorner> corners_;       // welded vertices
  std::vector<int> vertex_material_;       // bucket of each welded vertex
  std::map<Key, uint32_t> weld_;
  std::vector<std::string> materials_;     // bucket order = first use
  std::vector<Bucket> buckets_;
};

}  // namespace cohort::scene
