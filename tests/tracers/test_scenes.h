// Small procedural scenes and helpers for the tracer tests (header-only: the test folder globs
// *_test.cpp only).
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "cohort/commit/commit_buffer.h"
#include "cohort/core/frame_buffer.h"
#include "cohort/core/gpu_scene.h"
#include "cohort/core/image_output.h"
#include "cohort/core/tracer.h"
#include "cohort/core/view.h"
#include "cohort/scene/scene.h"

namespace cohort::test {

// Adds a quad (two triangles) with corners p0..p3 in order, all with vertex normal `normal`.
inline void add_quad(scene::Mesh& mesh, int material, glm::vec3 p0, glm::vec3 p1, glm::vec3 p2, glm::vec3 p3,
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

inline int add_diffuse_material(scene::Scene& scene, const std::string& name, glm::vec3 albedo) {
  scene::Material m;
  m.name = name;
  m.diffuse_color = glm::vec4(albedo, 1.0f);
  scene.materials.push_back(m);
  return static_cast<int>(scene.materials.size() - 1);
}

inline int add_image(scene::Scene& scene, const std::string& name, int w, int h,
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

inline int add_world_mesh(scene::Scene& scene, scene::Mesh mesh) {
  scene.meshes.push_back(std::move(mesh));
  scene.area_meshes.push_back(static_cast<int>(scene.meshes.size() - 1));
  return static_cast<int>(scene.meshes.size() - 1);
}

// A square floor in z = 0 spanning [-half, half]^2, facing +Z, as the scene's only area.
inline scene::Scene floor_scene(float half, glm::vec3 albedo) {
  scene::Scene s;
  s.name = "floor";
  int mat = add_diffuse_material(s, "floor", albedo);
  scene::Mesh mesh;
  mesh.name = "_area0";
  add_quad(mesh, mat, {-half, -half, 0}, {half, -half, 0}, {half, half, 0}, {-half, half, 0}, {0, 0, 1});
  add_world_mesh(s, std::move(mesh));
  return s;
}

// A closed cube [-half, half]^3 whose inside walls all have this albedo and emission.
inline scene::Scene furnace_box(float half, float albedo, float emission) {
  scene::Scene s;
  s.name = "furnace";
  scene::Material m;
  m.name = "wall";
  m.diffuse_color = glm::vec4(glm::vec3(albedo), 1.0f);
  m.emitter = true;
  m.emissive_color = glm::vec4(glm::vec3(emission), 1.0f);
  s.materials.push_back(m);
  scene::Mesh mesh;
  mesh.name = "_area0";
  float h = half;
  add_quad(mesh, 0, {-h, -h, -h}, {h, -h, -h}, {h, h, -h}, {-h, h, -h}, {0, 0, 1});
  add_quad(mesh, 0, {-h, -h, h}, {-h, h, h}, {h, h, h}, {h, -h, h}, {0, 0, -1});
  add_quad(mesh, 0, {-h, -h, -h}, {-h, h, -h}, {-h, h, h}, {-h, -h, h}, {1, 0, 0});
  add_quad(mesh, 0, {h, -h, -h}, {h, -h, h}, {h, h, h}, {h, h, -h}, {-1, 0, 0});
  add_quad(mesh, 0, {-h, -h, -h}, {-h, -h, h}, {h, -h, h}, {h, -h, -h}, {0, 1, 0});
  add_quad(mesh, 0, {-h, h, -h}, {h, h, -h}, {h, h, h}, {-h, h, h}, {0, -1, 0});
  add_world_mesh(s, std::move(mesh));
  return s;
}

// A pinhole camera at `origin` looking down -Z; image right is +X, image up is +Y.
inline KCamera camera_looking_down(glm::vec3 origin, float tan_half_fov, int width, int height) {
  KCamera c{};
  c.origin[0] = origin.x; c.origin[1] = origin.y; c.origin[2] = origin.z;
  c.forward[2] = -1.0f;
  c.right[0] = 1.0f;
  c.up[1] = 1.0f;
  c.width = static_cast<uint32_t>(width);
  c.height = static_cast<uint32_t>(height);
  c.tan_half_fov_x = tan_half_fov;
  c.tan_half_fov_y = tan_half_fov * float(height) / float(width);
  return c;
}

inline KFrameParams frame_params(uint32_t mode, uint32_t spp, uint32_t max_bounces, int height) {
  KFrameParams p{};
  p.frame_index = 0;
  p.spp = spp;
  p.max_bounces = max_bounces;
  p.light_samples = 1;
  p.firefly_clamp = 0.0f;
  p.spec_boost = 2.0f;
  p.mode = mode;
  p.row_begin = 0;
  p.row_end = static_cast<uint32_t>(height);
  p.soft_shadow_scale = 0.0f;
  p.rr_start = 100.0f;
  return p;
}

inline core::FrameBuffer render(core::Tracer& tracer, const scene::Scene& scene, const KCamera& camera,
                                const KFrameParams& params) {
  auto compiled = std::make_shared<commit::TracerScene>(core::compile_scene(scene).tracer_scene);
  tracer.apply(commit::CommitBuffer::full(compiled, 1));
  core::FrameBuffer fb;
  fb.resize(static_cast<int>(camera.width), static_cast<int>(camera.height));
  core::BandJob job;
  job.params = params;
  job.camera = camera;
  tracer.render_band(job, fb);
  return fb;
}

// Where the ray through image point (px, py) of a camera_looking_down meets z = 0.
inline glm::vec3 floor_point(const KCamera& c, float px, float py) {
  float sx = (2.0f * px / float(c.width) - 1.0f) * c.tan_half_fov_x;
  float sy = (1.0f - 2.0f * py / float(c.height)) * c.tan_half_fov_y;
  float h = c.origin[2];
  return {c.origin[0] + sx * h, c.origin[1] + sy * h, 0.0f};
}

inline glm::vec3 pixel(const core::FrameBuffer& fb, int x, int y) {
  const float* p = fb.row(y) + 4 * x;
  return {p[0], p[1], p[2]};
}

inline double mean_luminance(const core::FrameBuffer& fb) {
  double sum = 0.0;
  for (int y = 0; y < fb.height; ++y)
    for (int x = 0; x < fb.width; ++x) {
      glm::vec3 c = pixel(fb, x, y);
      sum += 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
    }
  return sum / (double(fb.width) * fb.height);
}


// A closed room (400 x 300 x 200) exercising most of the material and light paths: a checkered
// sRGB floor with a normal map and a specular map, an emissive panel, a pillar entity, an
// alpha-tested grate entity, an additive glow decal, a point light, a projected light with a gel and
// a falloff image, and a parallel light.
inline scene::Scene test_room() {
  scene::Scene s;
  s.name = "test_room";
  int checker = add_image(s, "textures/checker", 16, 16, [](int x, int y) {
    return ((x / 4 + y / 4) % 2) ? glm::u8vec4(200, 180, 150, 255) : glm::u8vec4(60, 80, 120, 255);
  });
  int bumps = add_image(s, "textures/bumps", 8, 8, [](int x, int y) {
    float nx = 0.4f * std::sin(float(x) * 0.8f), ny = 0.4f * std::cos(float(y) * 0.8f);
    float nz = std::sqrt(std::max(0.0f, 1.0f - nx * nx - ny * ny));
    return glm::u8vec4(uint8_t((nx * 0.5f + 0.5f) * 255), uint8_t((ny * 0.5f + 0.5f) * 255),
                       uint8_t((nz * 0.5f + 0.5f) * 255), 255);
  });
  s.images[size_t(bumps)].is_normal_map = true;
  int spec = add_image(s, "textures/spec", 4, 4, [](int x, int) {
    uint8_t v = uint8_t(60 * x + 30);
    return glm::u8vec4(v, v, v, 255);
  });
  int grate = add_image(s, "textures/grate", 8, 8, [](int x, int y) {
    return glm::u8vec4(150, 150, 160, ((x + y) % 3 == 0) ? 255 : 0);
  });
  int gel = add_image(s, "lights/gel", 4, 4, [](int x, int y) {
    return glm::u8vec4(uint8_t(x * 80), uint8_t(255 - y * 60), 200, 255);
  });
  int falloff = add_image(s, "lights/falloff", 16, 1, [](int x, int) {
    uint8_t v = uint8_t(255 - x * 15);
    return glm::u8vec4(v, v, v, 255);
  });

  scene::Material floor;
  floor.name = "floor";
  floor.diffuse_image = checker;
  floor.normal_image = bumps;
  floor.specular_image = spec;
  floor.tex_transform[0] = 4.0f;
  floor.tex_transform[4] = 3.0f;
  s.materials.push_back(floor);                                              // 0
  add_diffuse_material(s, "walls", glm::vec3(0.7f, 0.65f, 0.6f));           // 1
  scene::Material panel;
  panel.name = "panel";
  panel.diffuse_color = glm::vec4(0.2f, 0.2f, 0.2f, 1.0f);
  panel.emitter = true;
  panel.emissive_color = glm::vec4(2.0f, 1.5f, 0.8f, 1.0f);
  s.materials.push_back(panel);                                              // 2
  add_diffuse_material(s, "pillar", glm::vec3(0.5f, 0.6f, 0.5f));           // 3
  scene::Material grating;
  grating.name = "grate";
  grating.diffuse_image = grate;
  grating.alpha_test = true;
  grating.two_sided = true;
  s.materials.push_back(grating);                                            // 4
  scene::Material glow;
  glow.name = "glow";
  glow.blend = scene::BlendClass::Additive;
  glow.diffuse_color = glm::vec4(0.3f, 0.1f, 0.05f, 1.0f);
  glow.no_shadows = true;
  s.materials.push_back(glow);                                               // 5
  scene::Material gel_mat;
  gel_mat.name = "lights/gelfall";
  gel_mat.is_light_material = true;
  gel_mat.light_image = gel;
  gel_mat.falloff_image = falloff;
  s.materials.push_back(gel_mat);                                            // 6

  const float X = 200, Y = 150, Z = 200;
  scene::Mesh room;
  room.name = "_area0";
  add_quad(room, 0, {-X, -Y, 0}, {X, -Y, 0}, {X, Y, 0}, {-X, Y, 0}, {0, 0, 1});
  add_quad(room, 1, {-X, -Y, Z}, {-X, Y, Z}, {X, Y, Z}, {X, -Y, Z}, {0, 0, -1});
  add_quad(room, 1, {-X, -Y, 0}, {-X, Y, 0}, {-X, Y, Z}, {-X, -Y, Z}, {1, 0, 0});
  add_quad(room, 1, {X, -Y, 0}, {X, -Y, Z}, {X, Y, Z}, {X, Y, 0}, {-1, 0, 0});
  add_quad(room, 1, {-X, -Y, 0}, {-X, -Y, Z}, {X, -Y, Z}, {X, -Y, 0}, {0, 1, 0});
  add_quad(room, 1, {-X, Y, 0}, {X, Y, 0}, {X, Y, Z}, {-X, Y, Z}, {0, -1, 0});
  add_quad(room, 2, {X - 1, -40, 60}, {X - 1, -40, 140}, {X - 1, 40, 140}, {X - 1, 40, 60}, {-1, 0, 0});
  add_quad(room, 5, {-60, -60, 0.5f}, {60, -60, 0.5f}, {60, 60, 0.5f}, {-60, 60, 0.5f}, {0, 0, 1});
  add_world_mesh(s, std::move(room));

  scene::Mesh pillar;
  pillar.name = "pillar";
  const float w = 15, h = 120;
  add_quad(pillar, 3, {-w, -w, 0}, {w, -w, 0}, {w, -w, h}, {-w, -w, h}, {0, -1, 0});
  add_quad(pillar, 3, {w, -w, 0}, {w, w, 0}, {w, w, h}, {w, -w, h}, {1, 0, 0});
  add_quad(pillar, 3, {w, w, 0}, {-w, w, 0}, {-w, w, h}, {w, w, h}, {0, 1, 0});
  add_quad(pillar, 3, {-w, w, 0}, {-w, -w, 0}, {-w, -w, h}, {-w, w, h}, {-1, 0, 0});
  add_quad(pillar, 3, {-w, -w, h}, {w, -w, h}, {w, w, h}, {-w, w, h}, {0, 0, 1});
  s.meshes.push_back(pillar);
  scene::Entity p1;
  p1.name = "pillar1";
  p1.mesh = int(s.meshes.size() - 1);
  p1.origin = {-60, 40, 0};
  s.entities.push_back(p1);
  scene::Entity p2 = p1;
  p2.name = "pillar2";
  p2.origin = {80, -50, 0};
  float c = std::cos(0.6f), sn = std::sin(0.6f);
  p2.axis = glm::mat3(glm::vec3(c, sn, 0), glm::vec3(-sn, c, 0), glm::vec3(0, 0, 1));
  s.entities.push_back(p2);

  scene::Mesh grid;
  grid.name = "grate";
  add_quad(grid, 4, {-50, -50, 0}, {50, -50, 0}, {50, 50, 0}, {-50, 50, 0}, {0, 0, 1});
  s.meshes.push_back(grid);
  scene::Entity g;
  g.name = "grate1";
  g.mesh = int(s.meshes.size() - 1);
  g.origin = {0, 0, 160};
  s.entities.push_back(g);

  scene::Light point;
  point.name = "point";
  point.origin = {-100, -60, 150};
  point.radius = glm::vec3(350, 300, 250);
  point.color = glm::vec3(1.0f, 0.9f, 0.8f);
  s.lights.push_back(point);
  scene::Light spot;
  spot.name = "spot";
  spot.type = scene::LightType::Projected;
  spot.origin = {0, 0, 195};
  spot.target = {0, 0, -200};
  spot.right = {120, 0, 0};
  spot.up = {0, 120, 0};
  spot.material = 6;
  spot.color = glm::vec3(0.8f, 0.8f, 1.0f);
  s.lights.push_back(spot);
  scene::Light sun;
  sun.name = "sun";
  sun.type = scene::LightType::Parallel;
  sun.origin = {0, 0, 100};
  sun.radius = glm::vec3(400, 400, 400);
  sun.center = {0.3f, 0.2f, 1.0f};
  sun.color = glm::vec3(0.15f);
  s.lights.push_back(sun);
  s.player_start = {-180, 0, 0};
  return s;
}

// A camera inside test_room looking across it.
inline KCamera test_room_camera(int width, int height) {
  return core::make_camera({-190, -130, 120}, {35.0f, 20.0f}, 90.0f, width, height);  // 20 degrees down
}


// Writes an 8-bit preview (clamped, gamma 2.2) for looking at test images (COHORT_TEST_IMAGES=dir).
// Writes a PNG, or a PPM beside it in builds without an image library (the GPU machine's).
inline void write_preview(const std::string& requested, const core::FrameBuffer& fb) {
  std::string file = requested;
  if (!core::have_image_library() && file.size() > 4 && file.substr(file.size() - 4) == ".png")
    file = file.substr(0, file.size() - 4) + ".ppm";
  std::vector<uint8_t> rgba(size_t(fb.width) * fb.height * 4);
  for (size_t i = 0; i < rgba.size(); ++i) {
    float v = i % 4 == 3 ? 1.0f : std::pow(std::clamp(fb.rgba[i], 0.0f, 1.0f), 1.0f / 2.2f);
    rgba[i] = static_cast<uint8_t>(v * 255.0f + 0.5f);
  }
  core::write_ldr_image(file, fb.width, fb.height, rgba);
}

}  // namespace cohort::test
