#include <stdexcept>

#include "cohort/scene/md5.h"
#include "cohort/scene/model_file.h"
#include "ascii_case.h"
#include "model_builder.h"

namespace cohort::scene {

std::string canonical_decl_name(std::string_view name) {
  std::string out = lowercase(std::string(name));
  for (char& c : out)
    if (c == '\\') c = '/';
  size_t dot = out.rfind('.');
  size_t slash = out.rfind('/');
  if (dot != std::string::npos && (slash == std::string::npos || dot > slash)) out.erase(dot);
  return out;
}

ModelFile load_model_file(const Vfs& vfs, const std::string& name) {
  auto bytes = vfs.read(name);
  if (!bytes) throw std::runtime_error(name + ": model file not found");
  const std::string where = vfs.describe(name);
  if (ends_with_ignoring_case(name, ".ase")) return parse_ase(*bytes, where);
  if (ends_with_ignoring_case(name, ".lwo")) return parse_lwo(*bytes, where);
  if (ends_with_ignoring_case(name, ".md5mesh")) {
    Md5Mesh mesh = parse_md5mesh(*bytes, where);
    return skin_md5(mesh, bind_pose(mesh));
  }
  throw std::runtime_error(name + ": unsupported model format (ase, lwo and md5mesh are read)");
}

ModelFile placeholder_model(const std::string& name) {
  ModelBuilder builder(name);
  builder.begin_group();
  constexpr float h = 8.0f;
  // Each face as two triangles, clockwise seen from outside (face normal = (p2 - p0) x (p1 - p0)).
  const glm::vec3 normals[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (const glm::vec3& n : normals) {
    glm::vec3 u = std::abs(n.z) > 0.5f ? glm::vec3(1, 0, 0) : glm::vec3(0, 0, 1);
    glm::vec3 v = glm::cross(n, u);   // (u, v, n) right-handed
    glm::vec3 corners[4] = {h * (n - u - v), h * (n + u - v), h * (n + u + v), h * (n - u + v)};
    const glm::vec2 st[4] = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
    for (int tri = 0; tri < 2; ++tri) {
      int order[3] = {0, tri == 0 ? 2 : 3, tri == 0 ? 1 : 2};
      ModelCorner c[3];
      for (int k = 0; k < 3; ++k) {
        c[k].position = corners[order[k]];
        c[k].st = st[order[k]];
        c[k].normal = n;
        c[k].has_normal = true;
      }
      builder.add_triangle("_default", c);
    }
  }
  return builder.finish(false);
}

}  // namespace cohort::scene
