// The tracers' skinning data (kernel/skinning.h) for a scene mesh with an MD5 skin, and joints in the
// kernel's layout. Private to the core (WorldSync).
#pragma once

#include <vector>

#include "cohort/kernel/skinning.h"
#include "cohort/scene/scene.h"

namespace cohort::core {

// Per mesh, shared by every character drawn with it: indices relative to the vectors themselves
// (first_weight into weights, first_adjacent into adjacency, adjacency entries into triangles, triangle
// corners into the mesh's vertices).
struct MeshSkinData {
  std::vector<KSkinVertex> vertices;
  std::vector<KSkinWeight> weights;
  std::vector<KSkinTriangle> triangles;
  std::vector<uint32_t> adjacency;
};

// Adjacency for the normals skin_md5 regenerates: per surface, vertices at the same bind position share
// the triangles touching any of them, in triangle order (the kernel keeps those with a corner at the
// vertex's posed position). Throws std::runtime_error naming the mesh when its skin does not fit its vertices.
MeshSkinData mesh_skin_data(const scene::Mesh& mesh);

std::vector<KJoint> to_kjoints(const std::vector<scene::JointTransform>& joints);

}  // namespace cohort::core
