#include "model_builder.h"

#include <algorithm>
#include <cmath>

#include "cohort/scene/tangents.h"

namespace cohort::scene {

namespace {

glm::vec3 unit_or(glm::vec3 v, glm::vec3 fallback) {
  float length = glm::length(v);
  return length > 1e-12f && std::isfinite(length) ? v / length : fallback;
}

}  // namespace

void ModelBuilder::add_triangle(const std::string& material, const ModelCorner (&corners)[3]) {
  auto found = std::find(materials_.begin(), materials_.end(), material);
  int bucket = static_cast<int>(found - materials_.begin());
  if (found == materials_.end()) {
    materials_.push_back(material);
    buckets_.emplace_back();
  }
  for (const ModelCorner& c : corners) {
    // Material and group are part of the key: the engine welds per surface of one object or layer.
    Key key{group_ * 65536 + bucket, c.position.x, c.position.y, c.position.z, c.st.x, c.st.y,
            c.normal.x, c.normal.y, c.normal.z, c.has_normal, c.color.r, c.color.g, c.color.b, c.color.a};
    auto [it, added] = weld_.emplace(key, static_cast<uint32_t>(corners_.size()));
    if (added) {
      corners_.push_back(c);
      vertex_material_.push_back(bucket);
    }
    buckets_[static_cast<size_t>(bucket)].indices.push_back(it->second);
  }
  ++triangle_count_;
}

ModelFile ModelBuilder::finish(bool keep_colors) {
  ModelFile out;
  out.mesh.name = name_;
  // Generated normals: per surface, every corner at one position shares the sum of unit face normals.
  std::map<std::tuple<int, float, float, float>, glm::vec3> sums;
  for (size_t b = 0; b < buckets_.size(); ++b) {
    const auto& indices = buckets_[b].indices;
    for (size_t t = 0; t + 2 < indices.size(); t += 3) {
      const glm::vec3 &p0 = corners_[indices[t]].position, &p1 = corners_[indices[t + 1]].position,
                      &p2 = corners_[indices[t + 2]].position;
      glm::vec3 face = unit_or(glm::cross(p2 - p0, p1 - p0), glm::vec3(0.0f));
      for (int k = 0; k < 3; ++k) {
        const glm::vec3& p = corners_[indices[t + k]].position;
        sums[{int(b), p.x, p.y, p.z}] += face;
      }
    }
  }
  out.mesh.vertices.reserve(corners_.size());
  for (size_t v = 0; v < corners_.size(); ++v) {
    const ModelCorner& c = corners_[v];
    Vertex vertex;
    vertex.position = c.position;
    vertex.st = c.st;
    glm::vec3 normal = c.has_normal ? c.normal : sums[{vertex_material_[v], c.position.x, c.position.y, c.position.z}];
    vertex.normal = unit_or(normal, glm::vec3(0.0f, 0.0f, 1.0f));
    out.mesh.vertices.push_back(vertex);
    if (keep_colors) out.mesh.colors.push_back(pack_rgba8(c.color));
  }
  for (size_t b = 0; b < buckets_.size(); ++b) {
    Surface surface;
    surface.first_index = static_cast<uint32_t>(out.mesh.indices.size());
    surface.index_count = static_cast<uint32_t>(buckets_[b].indices.size());
    out.mesh.indices.insert(out.mesh.indices.end(), buckets_[b].indices.begin(), buckets_[b].indices.end());
    out.mesh.surfaces.push_back(surface);
    out.surface_materials.push_back(materials_[b]);
  }
  compute_tangents(out.mesh);
  return out;
}

}  // namespace cohort::scene
