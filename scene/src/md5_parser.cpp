// md5mesh / md5anim text readers (Model_md5.cpp idRenderModelMD5::LoadModel, Anim.cpp idMD5Anim::LoadAnim).
#include <cmath>
#include <stdexcept>

#include "cohort/scene/lexer.h"
#include "cohort/scene/md5.h"

namespace cohort::scene {

namespace {

constexpr size_t kMinJointBytes = 20;    // "\"\" -1 (0 0 0) (0 0 0)"
constexpr size_t kMinVertBytes = 14;     // "vert 0 (0 0) 0 1"
constexpr size_t kMinTriBytes = 11;      // "tri 0 0 0 0"
constexpr size_t kMinWeightBytes = 18;   // "weight 0 0 1 (0 0 0)"
constexpr size_t kMinFloatBytes = 2;     // "0 "
constexpr size_t kMinBoundsBytes = 14;   // "(0 0 0) (0 0 0)"

// The file's quaternion (x, y, z) with w recomputed, conjugated to column form.
glm::quat column_quat(const float xyz[3]) {
  float w = std::sqrt(std::fabs(1.0f - (xyz[0] * xyz[0] + xyz[1] * xyz[1] + xyz[2] * xyz[2])));
  return glm::quat(w, -xyz[0], -xyz[1], -xyz[2]);
}

void expect_version(Lexer& lex) {
  lex.expect("MD5Version");
  Token at = lex.peek();
  long long version = lex.expect_integer("MD5Version");
  if (version != 10) lex.fail(at, "MD5Version " + std::to_string(version) + " is not 10");
  if (lex.accept("commandline")) lex.expect_string("the commandline string");
}

size_t expect_counted(Lexer& lex, const char* keyword, size_t min_bytes, bool allow_zero = false) {
  lex.expect(keyword);
  Token at = lex.peek();
  size_t n = lex.expect_count(keyword, min_bytes);
  if (n == 0 && !allow_zero) lex.fail(at, std::string(keyword) + " must be positive");
  return n;
}

long long index_below(Lexer& lex, long long limit, const std::string& what, long long lowest = 0) {
  Token at = lex.peek();
  long long v = lex.expect_integer(what);
  if (v < lowest || v >= limit)
    lex.fail(at, what + " " + std::to_string(v) + " out of range (" + std::to_string(limit) + ")");
  return v;
}

void expect_numbered(Lexer& lex, const char* keyword, size_t expected) {
  lex.expect(keyword);
  Token at = lex.peek();
  long long n = lex.expect_integer(keyword);
  if (n != static_cast<long long>(expected))
    lex.fail(at, std::string(keyword) + " " + std::to_string(n) + " out of sequence (expected " +
                     std::to_string(expected) + ")");
}

Md5MeshPart parse_part(Lexer& lex, size_t joint_count) {
  Md5MeshPart part;
  lex.expect("{");
  if (lex.accept("name")) part.name = lex.expect_string("a mesh name");
  lex.expect("shader");
  part.shader = lex.expect_string("a shader name");
  size_t vert_count = expect_counted(lex, "numverts", kMinVertBytes);
  part.verts.resize(vert_count);
  std::vector<Token> vert_tokens(vert_count);
  for (size_t i = 0; i < vert_count; ++i) {
    vert_tokens[i] = lex.peek();
    expect_numbered(lex, "vert", i);
    float st[2];
    lex.expect_vector(st, 2, "a vertex st");
    Md5Vert& v = part.verts[i];
    v.st = {st[0], st[1]};
    v.first_weight = static_cast<int>(index_below(lex, 1ll << 30, "first weight"));
    Token count_at = lex.peek();
    v.weight_count = static_cast<int>(index_below(lex, 1ll << 30, "weight count"));
    if (v.weight_count == 0) lex.fail(count_at, "vertex " + std::to_string(i) + " has no weights");
  }
  size_t tri_count = expect_counted(lex, "numtris", kMinTriBytes);
  part.indices.reserve(tri_count * 3);
  for (size_t i = 0; i < tri_count; ++i) {
    expect_numbered(lex, "tri", i);
    for (int k = 0; k < 3; ++k)
      part.indices.push_back(static_cast<uint32_t>(index_below(lex, static_cast<long long>(vert_count), "triangle vertex")));
  }
  size_t weight_count = expect_counted(lex, "numweights", kMinWeightBytes);
  part.weights.resize(weight_count);
  for (size_t i = 0; i < weight_count; ++i) {
    expect_numbered(lex, "weight", i);
    Md5Weight& w = part.weights[i];
    w.joint = static_cast<int>(index_below(lex, static_cast<long long>(joint_count), "weight joint"));
    w.bias = lex.expect_float("weight bias");
    float offset[3];
    lex.expect_vector(offset, 3, "a weight offset");
    w.offset = {offset[0], offset[1], offset[2]};
  }
  for (size_t i = 0; i < vert_count; ++i) {
    const Md5Vert& v = part.verts[i];
    if (static_cast<size_t>(v.first_weight) + static_cast<size_t>(v.weight_count) > weight_count)
      lex.fail(vert_tokens[i], "vertex " + std::to_string(i) + " weights " + std::to_string(v.first_weight) + ".." +
                                   std::to_string(v.first_weight + v.weight_count - 1) + " run past numweights " +
                                   std::to_string(weight_count));
  }
  lex.expect("}");
  return part;
}

}  // namespace

Md5Mesh parse_md5mesh(std::string_view text, const std::string& file_name) {
  Lexer lex(text, file_name);
  expect_version(lex);
  Md5Mesh mesh;
  mesh.file = file_name;
  size_t joint_count = expect_counted(lex, "numJoints", kMinJointBytes);
  size_t part_count = expect_counted(lex, "numMeshes", kMinVertBytes);
  lex.expect("joints");
  lex.expect("{");
  mesh.joints.resize(joint_count);
  for (size_t i = 0; i < joint_count; ++i) {
    Md5Joint& j = mesh.joints[i];
    j.name = lex.expect_string("a joint name");
    // Parents precede their children (needed to concatenate poses in index order).
    j.parent = static_cast<int>(index_below(lex, static_cast<long long>(i), "joint parent", -1));
    float t[3], q[3];
    lex.expect_vector(t, 3, "a joint position");
    lex.expect_vector(q, 3, "a joint orientation");
    j.bind.position = {t[0], t[1], t[2]};
    j.bind.rotation = column_quat(q);
  }
  lex.expect("}");
  for (size_t m = 0; m < part_count; ++m) {
    lex.expect("mesh");
    mesh.parts.push_back(parse_part(lex, joint_count));
  }
  if (!lex.at_end()) lex.fail(lex.peek(), "unexpected '" + lex.peek().text + "' after the last mesh");
  return mesh;
}

int Md5Anim::length_ms() const {
  if (frames.size() <= 1 || frame_rate <= 0) return 0;
  return static_cast<int>(((static_cast<long long>(frames.size()) - 1) * 1000 + frame_rate - 1) / frame_rate);
}

Md5Anim parse_md5anim(std::string_view text, const std::string& file_name) {
  Lexer lex(text, file_name);
  expect_version(lex);
  Md5Anim anim;
  anim.file = file_name;
  size_t frame_count = expect_counted(lex, "numFrames", kMinBoundsBytes);
  size_t joint_count = expect_counted(lex, "numJoints", kMinJointBytes);
  lex.expect("frameRate");
  Token rate_at = lex.peek();
  long long rate = lex.expect_integer("frameRate");
  if (rate <= 0 || rate > 10000) lex.fail(rate_at, "frameRate " + std::to_string(rate) + " out of range");
  anim.frame_rate = static_cast<int>(rate);
  lex.expect("numAnimatedComponents");
  Token components_at = lex.peek();
  size_t components = lex.expect_count("numAnimatedComponents", 0);
  if (components > joint_count * 6)
    lex.fail(components_at, "numAnimatedComponents " + std::to_string(components) + " exceeds 6 per joint");
  if (components > 0 && frame_count > lex.bytes_left() / (components * kMinFloatBytes) + 1)
    lex.fail(components_at, "numFrames x numAnimatedComponents is more than the file can hold");
  anim.animated_components = static_cast<int>(components);

  lex.expect("hierarchy");
  lex.expect("{");
  anim.joints.resize(joint_count);
  for (size_t i = 0; i < joint_count; ++i) {
    Md5AnimJoint& j = anim.joints[i];
    j.name = lex.expect_string("a joint name");
    Token parent_at = lex.peek();
    j.parent = static_cast<int>(index_below(lex, static_cast<long long>(i), "joint parent", -1));
    if (i > 0 && j.parent < 0) lex.fail(parent_at, "joint " + j.name + " is a second root");
    Token flags_at = lex.peek();
    long long flags = lex.expect_integer("joint flags");
    if (flags < 0 || flags > 63) lex.fail(flags_at, "joint flags " + std::to_string(flags) + " out of range (0..63)");
    j.flags = static_cast<int>(flags);
    Token first_at = lex.peek();
    long long first = lex.expect_integer("first component");
    int used = 0;
    for (int bit = 0; bit < 6; ++bit) used += (flags >> bit) & 1;
    if (used > 0 && (first < 0 || first + used > static_cast<long long>(components)))
      lex.fail(first_at, "joint " + j.name + " components " + std::to_string(first) + "+" + std::to_string(used) +
                             " past numAnimatedComponents " + std::to_string(components));
    j.first_component = used > 0 ? static_cast<int>(first) : 0;
  }
  lex.expect("}");

  lex.expect("bounds");
  lex.expect("{");
  for (size_t f = 0; f < frame_count; ++f) {
    float lo[3], hi[3];
    lex.expect_vector(lo, 3, "a bounds minimum");
    lex.expect_vector(hi, 3, "a bounds maximum");
    anim.bounds.emplace_back(glm::vec3(lo[0], lo[1], lo[2]), glm::vec3(hi[0], hi[1], hi[2]));
  }
  lex.expect("}");

  lex.expect("baseframe");
  lex.expect("{");
  anim.base_frame.resize(joint_count);
  for (size_t i = 0; i < joint_count; ++i) {
    float t[3], q[3];
    lex.expect_vector(t, 3, "a baseframe position");
    lex.expect_vector(q, 3, "a baseframe orientation");
    anim.base_frame[i].position = {t[0], t[1], t[2]};
    anim.base_frame[i].rotation = column_quat(q);
  }
  lex.expect("}");

  anim.frames.resize(frame_count);
  for (size_t f = 0; f < frame_count; ++f) {
    expect_numbered(lex, "frame", f);
    lex.expect("{");
    anim.frames[f].resize(components);
    for (size_t c = 0; c < components; ++c) anim.frames[f][c] = lex.expect_float("a frame component");
    lex.expect("}");
  }
  if (!lex.at_end()) lex.fail(lex.peek(), "unexpected '" + lex.peek().text + "' after the last frame");

  // Root motion as the engine keeps it: the baseframe root sits at the origin and animated root
  // translation is relative to where the baseframe had it.
  if (components > 0) {
    const Md5AnimJoint& root = anim.joints[0];
    int offset = root.first_component;
    for (int axis = 0; axis < 3; ++axis) {
      if (!(root.flags & (1 << axis))) continue;
      for (auto& frame : anim.frames) frame[static_cast<size_t>(offset)] -= anim.base_frame[0].position[axis];
      anim.total_delta[axis] = anim.frames.back()[static_cast<size_t>(offset)];
      ++offset;
    }
  }
  anim.base_frame[0].position = glm::vec3(0.0f);
  return anim;
}

void check_anim_matches(const Md5Mesh& mesh, const Md5Anim& anim) {
  const std::string both = anim.file + " does not fit " + mesh.file + ": ";
  if (mesh.joints.size() != anim.joints.size())
    throw std::runtime_error(both + std::to_string(anim.joints.size()) + " joints, the mesh has " +
                             std::to_string(mesh.joints.size()));
  for (size_t i = 0; i < mesh.joints.size(); ++i) {
    if (mesh.joints[i].name != anim.joints[i].name)
      throw std::runtime_error(both + "joint " + std::to_string(i) + " is '" + anim.joints[i].name + "', the mesh has '" +
                               mesh.joints[i].name + "'");
    if (mesh.joints[i].parent != anim.joints[i].parent)
      throw std::runtime_error(both + "joint " + mesh.joints[i].name + " has parent " +
                               std::to_string(anim.joints[i].parent) + ", the mesh has " +
                               std::to_string(mesh.joints[i].parent));
  }
}

}  // namespace cohort::scene
