// MD5 skeletal models (md5mesh) and animations (md5anim), read and evaluated as the engine does
// (renderer/Model_md5.cpp, game/anim/Anim.cpp; doom3-content.md section 5). Quaternions are kept in
// column-vector form: the file's (x, y, z) with w = +sqrt(|1 - x^2 - y^2 - z^2|) is conjugated, because
// idTech applies its rotation matrices to row vectors.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "cohort/scene/model_file.h"

namespace cohort::scene {

struct Md5Joint {
  std::string name;
  int parent = -1;
  JointTransform bind;                          // model space, as the md5mesh stores it
};

struct Md5Weight {
  int joint = 0;
  float bias = 0.0f;
  glm::vec3 offset{0.0f};
};

struct Md5Vert {
  glm::vec2 st{0.0f};
  int first_weight = 0, weight_count = 0;
};

struct Md5MeshPart {
  std::string name, shader;                     // shader: the material name
  std::vector<Md5Vert> verts;
  std::vector<uint32_t> indices;                // as stored (already clockwise-front)
  std::vector<Md5Weight> weights;
};

struct Md5Mesh {
  std::string file;
  std::vector<Md5Joint> joints;
  std::vector<Md5MeshPart> parts;
};

struct Md5AnimJoint {
  std::string name;
  int parent = -1;
  int flags = 0;                                // bit0..5: Tx Ty Tz Qx Qy Qz animated
  int first_component = 0;
};

struct Md5Anim {
  std::string file;
  int frame_rate = 24;
  int animated_components = 0;
  std::vector<Md5AnimJoint> joints;
  std::vector<std::pair<glm::vec3, glm::vec3>> bounds;   // per frame: min, max
  std::vector<JointTransform> base_frame;      // parent-relative; root translation zeroed at load
  std::vector<std::vector<float>> frames;      // animated components per frame, root offset removed
  glm::vec3 total_delta{0.0f};                  // root translation of the last frame (moves per cycle)
  int frame_count() const { return static_cast<int>(frames.size()); }
  // Milliseconds of one cycle: ((frames - 1) * 1000 + fps - 1) / fps.
  int length_ms() const;
};

// Throw ParseError naming file:line for malformed input (counts, indices, weights out of range).
Md5Mesh parse_md5mesh(std::string_view text, const std::string& file_name);
Md5Anim parse_md5anim(std::string_view text, const std::string& file_name);
// The engine's CheckModelHierarchy: the same joint count, names and parents. Throws std::runtime_error
// naming both files and the first difference.
void check_anim_matches(const Md5Mesh& mesh, const Md5Anim& anim);

// The md5mesh's own pose (model space).
std::vector<JointTransform> bind_pose(const Md5Mesh& mesh);
// The animation at time_ms since its start, looping (ConvertTimeToFrame + BlendJoints): parent-relative
// joints interpolated between two frames, then concatenated to model space. The per-cycle root motion
// (total_delta per finished cycle) is left to the caller, as the engine leaves it to the entity.
std::vector<JointTransform> anim_pose(const Md5Anim& anim, int time_ms);
// One frame exactly, model space.
std::vector<JointTransform> anim_frame_pose(const Md5Anim& anim, int frame);

// The mesh skinned by a model-space pose (one transform per joint): positions = sum of bias * (R offset + T)
// over each vertex's weights, normals regenerated from the skinned triangles, tangents derived; one
// surface per md5 mesh part with its shader as material. `scale` != 0 scales the mesh (entity parm8).
ModelFile skin_md5(const Md5Mesh& mesh, const std::vector<JointTransform>& pose, float scale = 0.0f);
// The mesh's weights in the order skin_md5 lays its vertices out (parts one after another), for skinning
// elsewhere (the tracers): skin_md5's positions are the sum over these weights.
MeshSkin md5_mesh_skin(const Md5Mesh& mesh);

}  // namespace cohort::scene
