// Evaluating MD5 poses and skinning (Anim.cpp ConvertTimeToFrame / GetInterpolatedFrame, Simd_Generic.cpp
// TransformVerts, tr_trisurf.cpp R_DeriveTangents for the regenerated normals).
#include <cmath>
#include <map>
#include <tuple>

#include "cohort/scene/md5.h"
#include "cohort/scene/tangents.h"

namespace cohort::scene {

namespace {

// The joint's parent-relative transform in one frame: baseframe values replaced by the animated ones.
JointTransform frame_joint(const Md5Anim& anim, size_t joint, int frame) {
  const Md5AnimJoint& info = anim.joints[joint];
  JointTransform out = anim.base_frame[joint];
  if (info.flags == 0 || anim.frames.empty()) return out;
  const std::vector<float>& values = anim.frames[static_cast<size_t>(frame)];
  size_t at = static_cast<size_t>(info.first_component);
  for (int axis = 0; axis < 3; ++axis)
    if (info.flags & (1 << axis)) out.position[axis] = values[at++];
  if (info.flags & (7 << 3)) {
    // The stored quaternion is file (x, y, z); the base frame keeps its column-form conjugate.
    float q[3] = {-out.rotation.x, -out.rotation.y, -out.rotation.z};
    for (int axis = 0; axis < 3; ++axis)
      if (info.flags & (8 << axis)) q[axis] = values[at++];
    float w = std::sqrt(std::fabs(1.0f - (q[0] * q[0] + q[1] * q[1] + q[2] * q[2])));
    out.rotation = glm::quat(w, -q[0], -q[1], -q[2]);
  }
  return out;
}

// idQuat::Slerp: shortest arc, linear when the quaternions are nearly equal.
glm::quat slerp(glm::quat from, glm::quat to, float t) {
  if (t <= 0.0f) return from;
  if (t >= 1.0f) return to;
  float cosom = glm::dot(from, to);
  if (cosom < 0.0f) {
    to = -to;
    cosom = -cosom;
  }
  float scale0 = 1.0f - t, scale1 = t;
  if (1.0f - cosom > 1e-6f) {
    float omega = std::acos(cosom), sinom = std::sin(omega);
    scale0 = std::sin((1.0f - t) * omega) / sinom;
    scale1 = std::sin(t * omega) / sinom;
  }
  return glm::quat(scale0 * from.w + scale1 * to.w, scale0 * from.x + scale1 * to.x, scale0 * from.y + scale1 * to.y,
                   scale0 * from.z + scale1 * to.z);
}

std::vector<JointTransform> to_model_space(const Md5Anim& anim, std::vector<JointTransform> local) {
  for (size_t i = 0; i < local.size(); ++i) {
    int parent = anim.joints[i].parent;
    if (parent < 0) continue;
    const JointTransform& p = local[static_cast<size_t>(parent)];
    local[i].position = p.rotation * local[i].position + p.position;
    local[i].rotation = glm::normalize(p.rotation * local[i].rotation);
  }
  return local;
}

}  // namespace

std::vector<JointTransform> bind_pose(const Md5Mesh& mesh) {
  std::vector<JointTransform> pose;
  pose.reserve(mesh.joints.size());
  for (const Md5Joint& j : mesh.joints) pose.push_back(j.bind);
  return pose;
}

std::vector<JointTransform> anim_frame_pose(const Md5Anim& anim, int frame) {
  int last = std::max(0, anim.frame_count() - 1);
  frame = std::min(std::max(frame, 0), last);
  std::vector<JointTransform> local(anim.joints.size());
  for (size_t j = 0; j < local.size(); ++j) local[j] = frame_joint(anim, j, frame);
  return to_model_space(anim, std::move(local));
}

std::vector<JointTransform> anim_pose(const Md5Anim& anim, int time_ms) {
  const int frames = anim.frame_count();
  if (time_ms <= 0 || frames <= 1) return anim_frame_pose(anim, 0);
  const long long ft = static_cast<long long>(time_ms) * anim.frame_rate;
  const long long n = ft / 1000;
  const int frame1 = static_cast<int>(n % (frames - 1));
  const int frame2 = frame1 + 1;
  const float lerp = static_cast<float>(ft % 1000) / 1000.0f;
  std::vector<JointTransform> local(anim.joints.size());
  for (size_t j = 0; j < local.size(); ++j) {
    JointTransform a = frame_joint(anim, j, frame1), b = frame_joint(anim, j, frame2);
    local[j].position = a.position + (b.position - a.position) * lerp;
    local[j].rotation = slerp(a.rotation, b.rotation, lerp);
  }
  return to_model_space(anim, std::move(local));
}

ModelFile skin_md5(const Md5Mesh& mesh, const std::vector<JointTransform>& pose, float scale) {
  ModelFile out;
  out.mesh.name = mesh.file;
  if (pose.size() != mesh.joints.size())
    throw std::runtime_error(mesh.file + ": a pose of " + std::to_string(pose.size()) + " joints for a mesh of " +
                             std::to_string(mesh.joints.size()));
  const float s = scale != 0.0f ? scale : 1.0f;
  for (const Md5MeshPart& part : mesh.parts) {
    const uint32_t base = static_cast<uint32_t>(out.mesh.vertices.size());
    for (const Md5Vert& v : part.verts) {
      glm::vec3 position(0.0f);
      for (int w = 0; w < v.weight_count; ++w) {
        const Md5Weight& weight = part.weights[static_cast<size_t>(v.first_weight + w)];
        const JointTransform& joint = pose[static_cast<size_t>(weight.joint)];
        position += s * weight.bias * (joint.rotation * weight.offset + joint.position);
      }
      Vertex vertex;
      vertex.position = position;
      vertex.st = v.st;
      out.mesh.vertices.push_back(vertex);
    }
    // Normals from the skinned triangles: unit face normals summed over every vertex at one position.
    std::map<std::tuple<float, float, float>, glm::vec3> sums;
    for (size_t t = 0; t + 2 < part.indices.size(); t += 3) {
      const glm::vec3& p0 = out.mesh.vertices[base + part.indices[t]].position;
      const glm::vec3& p1 = out.mesh.vertices[base + part.indices[t + 1]].position;
      const glm::vec3& p2 = out.mesh.vertices[base + part.indices[t + 2]].position;
      glm::vec3 face = glm::cross(p2 - p0, p1 - p0);
      float length = glm::length(face);
      if (length > 0.0f) face /= length;
      for (int k = 0; k < 3; ++k) {
        const glm::vec3& p = out.mesh.vertices[base + part.indices[t + static_cast<size_t>(k)]].position;
        sums[{p.x, p.y, p.z}] += face;
      }
    }
    for (size_t v = base; v < out.mesh.vertices.size(); ++v) {
      Vertex& vertex = out.mesh.vertices[v];
      glm::vec3 n = sums[{vertex.position.x, vertex.position.y, vertex.position.z}];
      float length = glm::length(n);
      vertex.normal = length > 0.0f ? n / length : glm::vec3(0.0f, 0.0f, 1.0f);
    }
    Surface surface;
    surface.first_index = static_cast<uint32_t>(out.mesh.indices.size());
    surface.index_count = static_cast<uint32_t>(part.indices.size());
    for (uint32_t i : part.indices) out.mesh.indices.push_back(base + i);
    out.mesh.surfaces.push_back(surface);
    out.surface_materials.push_back(canonical_decl_name(part.shader));
  }
  compute_tangents(out.mesh);
  return out;
}

MeshSkin md5_mesh_skin(const Md5Mesh& mesh) {
  MeshSkin skin;
  skin.joint_count = static_cast<int>(mesh.joints.size());
  for (const Md5MeshPart& part : mesh.parts) {
    const uint32_t base = static_cast<uint32_t>(skin.weights.size());
    for (const Md5Vert& v : part.verts) {
      skin.first_weight.push_back(base + static_cast<uint32_t>(v.first_weight));
      skin.weight_count.push_back(static_cast<uint32_t>(v.weight_count));
    }
    for (const Md5Weight& w : part.weights) skin.weights.push_back({w.joint, w.bias, w.offset});
  }
  return skin;
}

}  // namespace cohort::scene
