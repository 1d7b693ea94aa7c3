#include "skin_data.h"

#include <cstring>
#include <map>
#include <stdexcept>
#include <string>

namespace cohort::core {
namespace {

// Bit patterns of a vertex's bind position.
std::vector<uint32_t> position_key(const scene::Mesh& mesh, uint32_t v) {
  std::vector<uint32_t> key;
  auto put = [&key](float f) {
    uint32_t bits;
    std::memcpy(&bits, &f, 4);
    key.push_back(bits);
  };
  const glm::vec3& p = mesh.vertices[v].position;
  put(p.x), put(p.y), put(p.z);
  return key;
}

}  // namespace

MeshSkinData mesh_skin_data(const scene::Mesh& mesh) {
  if (!mesh.skin) throw std::runtime_error("mesh '" + mesh.name + "' has no skin");
  const scene::MeshSkin& skin = *mesh.skin;
  const size_t count = mesh.vertices.size();
  if (skin.first_weight.size() != count || skin.weight_count.size() != count)
    throw std::runtime_error("mesh '" + mesh.name + "': its skin weighs " + std::to_string(skin.first_weight.size()) +
                             " vertices of " + std::to_string(count));
  MeshSkinData out;
  out.weights.reserve(skin.weights.size());
  for (const scene::SkinWeight& w : skin.weights) {
    if (w.joint < 0 || w.joint >= skin.joint_count)
      throw std::runtime_error("mesh '" + mesh.name + "': a weight names joint " + std::to_string(w.joint) + " of " +
                               std::to_string(skin.joint_count));
    KSkinWeight k{};
    k.offset[0] = w.offset.x, k.offset[1] = w.offset.y, k.offset[2] = w.offset.z;
    k.bias = w.bias;
    k.joint = uint32_t(w.joint);
    out.weights.push_back(k);
  }
  std::vector<int> group_of(count, -1);
  std::vector<std::vector<uint32_t>> groups;
  for (const scene::Surface& surface : mesh.surfaces) {
    std::map<std::vector<uint32_t>, int> by_key;
    for (uint32_t i = 0; i + 2 < surface.index_count; i += 3) {
      const size_t first = size_t(surface.first_index) + i;
      if (first + 2 >= mesh.indices.size()) throw std::runtime_error("mesh '" + mesh.name + "' has a surface past its indices");
      KSkinTriangle t{mesh.indices[first], mesh.indices[first + 1], mesh.indices[first + 2], 0u};
      const uint32_t triangle = uint32_t(out.triangles.size());
      out.triangles.push_back(t);
      int seen[3] = {-1, -1, -1};
      for (int k = 0; k < 3; ++k) {
        const uint32_t v = k == 0 ? t.v0 : k == 1 ? t.v1 : t.v2;
        if (v >= count) throw std::runtime_error("mesh '" + mesh.name + "' indexes a vertex it does not have");
        if (skin.first_weight[v] + uint64_t(skin.weight_count[v]) > skin.weights.size())
          throw std::runtime_error("mesh '" + mesh.name + "': vertex " + std::to_string(v) + "'s weights run past the " +
                                   std::to_string(skin.weights.size()) + " weights");
        if (group_of[v] < 0) {
          auto [it, inserted] = by_key.emplace(position_key(mesh, v), int(groups.size()));
          if (inserted) groups.emplace_back();
          group_of[v] = it->second;
        }
        const int g = group_of[v];
        if (g == seen[0] || g == seen[1]) continue;  // one entry per group, as the vertex sums it once
        seen[k] = g;
        groups[size_t(g)].push_back(triangle);
      }
    }
  }
  out.vertices.resize(count);
  std::vector<uint32_t> group_first(groups.size());
  for (size_t g = 0; g < groups.size(); ++g) {
    group_first[g] = uint32_t(out.adjacency.size());
    out.adjacency.insert(out.adjacency.end(), groups[g].begin(), groups[g].end());
  }
  for (size_t v = 0; v < count; ++v) {
    KSkinVertex& k = out.vertices[v];
    k.first_weight = skin.first_weight[v];
    k.weight_count = skin.weight_count[v];
    const int g = group_of[v];
    k.first_adjacent = g < 0 ? 0u : group_first[size_t(g)];
    k.adjacent_count = g < 0 ? 0u : uint32_t(groups[size_t(g)].size());
  }
  return out;
}

std::vector<KJoint> to_kjoints(const std::vector<scene::JointTransform>& joints) {
  std::vector<KJoint> out(joints.size());
  for (size_t j = 0; j < joints.size(); ++j) {
    const scene::JointTransform& t = joints[j];
    out[j] = KJoint{{t.rotation.x, t.rotation.y, t.rotation.z, t.rotation.w}, {t.position.x, t.position.y, t.position.z}, 0.0f};
  }
  return out;
}

}  // namespace cohort::core
