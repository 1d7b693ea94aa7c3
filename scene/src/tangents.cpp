#include "cohort/scene/tangents.h"

#include <cmath>

namespace cohort::scene {

namespace {

glm::vec3 any_perpendicular(const glm::vec3& n) {
  glm::vec3 helper = std::fabs(n.z) < 0.9f ? glm::vec3(0, 0, 1) : glm::vec3(1, 0, 0);
  glm::vec3 t = glm::cross(helper, n);
  float len = glm::length(t);
  return len > 1e-12f ? t / len : glm::vec3(1, 0, 0);
}

}  // namespace

void compute_tangents(Mesh& mesh) {
  const size_t n = mesh.vertices.size();
  std::vector<glm::vec3> tan_s(n, glm::vec3(0.0f)), tan_t(n, glm::vec3(0.0f));
  for (size_t i = 0; i + 2 < mesh.indices.size(); i += 3) {
    uint32_t a = mesh.indices[i], b = mesh.indices[i + 1], c = mesh.indices[i + 2];
    if (a >= n || b >= n || c >= n) continue;
    const Vertex &va = mesh.vertices[a], &vb = mesh.vertices[b], &vc = mesh.vertices[c];
    glm::vec3 e1 = vb.position - va.position, e2 = vc.position - va.position;
    glm::vec2 d1 = vb.st - va.st, d2 = vc.st - va.st;
    float det = d1.x * d2.y - d2.x * d1.y;
    if (!std::isfinite(det) || std::fabs(det) < 1e-12f) continue;
    float r = 1.0f / det;
    glm::vec3 sdir = (e1 * d2.y - e2 * d1.y) * r;
    glm::vec3 tdir = (e2 * d1.x - e1 * d2.x) * r;
    if (!std::isfinite(sdir.x + sdir.y + sdir.z + tdir.x + tdir.y + tdir.z)) continue;
    for (uint32_t v : {a, b, c}) {
      tan_s[v] += sdir;
      tan_t[v] += tdir;
    }
  }
  for (size_t v = 0; v < n; ++v) {
    glm::vec3 normal = mesh.vertices[v].normal;
    float nlen = glm::length(normal);
    normal = (std::isfinite(nlen) && nlen > 1e-12f) ? normal / nlen : glm::vec3(0, 0, 1);
    glm::vec3 t = tan_s[v] - normal * glm::dot(normal, tan_s[v]);
    float tlen = glm::length(t);
    glm::vec3 tangent = (std::isfinite(tlen) && tlen > 1e-6f) ? t / tlen : any_perpendicular(normal);
    float sign = glm::dot(glm::cross(normal, tangent), tan_t[v]) < 0.0f ? -1.0f : 1.0f;
    mesh.vertices[v].tangent = glm::vec4(tangent, sign);
  }
}

}  // namespace cohort::scene
