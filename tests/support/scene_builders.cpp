#include "cohort/test_support/scene_builders.h"

namespace cohort::test {

void add_quad(scene::Mesh& mesh, int material, glm::vec3 p0, glm::vec3 p1, glm::vec3 p2, glm::vec3 p3,
              glm::vec3 normal) {
  uint32_t base = static_cast<uint32_t>(mesh.vertices.size());
  glm::vec3 ps[4] = {p0, p1, p2, p3};
  glm::vec2 st[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  glm::vec3 tangent = glm::normalize(p1 - p0);
  for (int i = 0; i < 4; ++i) {
    scene::Vertex v;
    v.position = ps[i];
    v.st = st[i];
    v.normal = normal;
    v.tangent = glm::vec4(tangent, 1.0f);
    mesh.vertices.push_back(v);
  }
  scene::Surface surface;
  surface.material = material;
  surface.first_index = static_cast<uint32_t>(mesh.indices.size());
  surface.index_count = 6;
  for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) mesh.indices.push_back(base + i);
  mesh.surfaces.push_back(surface);
}

scene::Mesh box_mesh(const std::string& name, glm::vec3 half, int material) {
  scene::Mesh m;
  m.name = name;
  for (int i = 0; i < 8; ++i) {
    scene::Vertex v;
    v.position = {(i & 1 ? 1 : -1) * half.x, (i & 2 ? 1 : -1) * half.y, (i & 4 ? 1 : -1) * half.z};
    v.st = {float(i & 1), float((i >> 1) & 1)};
    m.vertices.push_back(v);
  }
  const uint32_t faces[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
  for (const auto& f : faces)
    for (uint32_t i : {f[0], f[1], f[2], f[0], f[2], f[3]}) m.indices.push_back(i);
  m.surfaces.push_back({material, 0, uint32_t(m.indices.size())});
  return m;
}

scene::Image checker(const std::string& name, int size) {
  scene::Image img;
  img.name = name;
  img.width = img.height = size;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x)
      for (int c = 0; c < 4; ++c) img.rgba.push_back(uint8_t(((x + y) & 1) ? 255 : 40 * c));
  return img;
}

int add_diffuse_material(scene::Scene& scene, const std::string& name, glm::vec3 albedo) {
  scene::Material m;
  m.name = name;
  m.diffuse_color = glm::vec4(albedo, 1.0f);
  scene.materials.push_back(m);
  return static_cast<int>(scene.materials.size() - 1);
}

int add_image(scene::Scene& scene, const std::string& name, int w, int h,
              const std::function<glm::u8vec4(int, int)>& texel) {
  scene::Image img;
  img.name = name;
  img.width = w;
  img.height = h;
  img.rgba.resize(size_t(w) * h * 4);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      glm::u8vec4 c = texel(x, y);
      for (int k = 0; k < 4; ++k) img.rgba[(size_t(y) * w + x) * 4 + k] = c[k];
    }
  scene.images.push_back(img);
  return static_cast<int>(scene.images.size() - 1);
}

int add_world_mesh(scene::Scene& scene, scene::Mesh mesh) {
  scene.meshes.push_back(std::move(mesh));
  scene.area_meshes.push_back(static_cast<int>(scene.meshes.size() - 1));
  return static_cast<int>(scene.meshes.size() - 1);
}

int add_occluder(scene::Scene& scene, int material) {
  scene::Mesh m;
  m.name = "occluder";
  add_quad(m, material, {-20, -20, 0}, {20, -20, 0}, {20, 20, 0}, {-20, 20, 0}, {0, 0, 1});
  scene.meshes.push_back(m);
  scene::Entity e;
  e.name = "occluder";
  e.mesh = static_cast<int>(scene.meshes.size() - 1);
  e.origin = {0, 0, 50};
  scene.entities.push_back(e);
  return static_cast<int>(scene.entities.size() - 1);
}

scene::Light point_light(glm::vec3 origin, glm::vec3 radius, glm::vec3 colour) {
  scene::Light l;
  l.name = "light";
  l.origin = origin;
  l.radius = radius;
  l.color = colour;
  return l;
}

KLight kernel_point_light_about_origin(float half_size) {
  KLight light{};
  light.type = K_LIGHT_POINT;
  const float slope = 0.5f / half_size;  // s = slope x + 0.5: 0 to 1 over [-half_size, half_size]
  for (int k = 0; k < 3; ++k) {
    light.radius[k] = half_size;
    light.color[k] = 1.0f;
  }
  light.plane_s[0] = light.plane_t[1] = light.plane_f[2] = slope;
  light.plane_s[3] = light.plane_t[3] = light.plane_f[3] = 0.5f;
  light.plane_q[3] = 1.0f;
  return light;
}

}  // namespace cohort::test
