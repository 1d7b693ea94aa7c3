#include "cohort/test_support/test_scenes.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "cohort/scene/scenario.h"
#include "cohort/test_support/scene_builders.h"

namespace cohort::test {

scene::Scene small_test_map() {
  const scene::ScenarioOptions names;
  scene::Scene s;
  s.name = "small";
  s.images.push_back(checker("textures/test/checker", 4));
  scene::Material floor;
  floor.name = "textures/test/floor";
  floor.diffuse_image = 0;
  s.materials.push_back(floor);
  scene::Material light_shader;
  light_shader.name = "lights/test/flicker";
  light_shader.is_light_material = true;
  s.materials.push_back(light_shader);
  s.meshes.push_back(box_mesh("_area0", {512, 512, 8}, 0));
  s.area_meshes.push_back(0);
  s.meshes.push_back(box_mesh("door_main", {4, 32, 48}, 0));
  s.meshes.push_back(box_mesh("fan_spin", {32, 32, 2}, 0));
  scene::Entity player;
  player.name = "info_player_start_1";
  player.classname = "info_player_start";
  s.entities.push_back(player);
  scene::Entity door;
  door.name = names.door;
  door.classname = "func_door";
  door.mesh = 1;
  door.origin = {128, 0, 48};
  s.entities.push_back(door);
  scene::Entity fan;
  fan.name = names.fan;
  fan.classname = "func_rotating";
  fan.mesh = 2;
  fan.origin = {0, 128, 120};
  s.entities.push_back(fan);
  scene::Light flicker;
  flicker.name = names.flicker;
  flicker.origin = {0, 0, 100};
  flicker.color = {1.0f, 0.8f, 0.6f};
  flicker.material = 1;
  s.lights.push_back(flicker);
  scene::Light fill;
  fill.name = "light_fill";
  fill.origin = {-200, 0, 100};
  fill.radius = glm::vec3(500.0f);
  s.lights.push_back(fill);
  s.player_start = {-100, 0, 40};
  return s;
}

scene::Scene test_room() {
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

scene::Scene floor_scene(float half, glm::vec3 albedo) {
  scene::Scene s;
  s.name = "floor";
  int mat = add_diffuse_material(s, "floor", albedo);
  scene::Mesh mesh;
  mesh.name = "_area0";
  add_quad(mesh, mat, {-half, -half, 0}, {half, -half, 0}, {half, half, 0}, {-half, half, 0}, {0, 0, 1});
  add_world_mesh(s, std::move(mesh));
  return s;
}

scene::Scene furnace_box(float half, float albedo, float emission) {
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

scene::Scene many_lights_floor(int point_lights, int projected_lights, unsigned seed) {
  scene::Scene s = floor_scene(1000.0f, {0.7f, 0.7f, 0.7f});
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-950.0f, 950.0f), radius(150.0f, 450.0f), height(30.0f, 160.0f),
      colour(0.05f, 1.0f);
  for (int i = 0; i < point_lights; ++i)
    s.lights.push_back(point_light({pos(rng), pos(rng), height(rng)}, {radius(rng), radius(rng), radius(rng)},
                                   {colour(rng), colour(rng), colour(rng)}));
  for (int i = 0; i < projected_lights; ++i) {
    scene::Light l;
    l.name = "spot";
    l.type = scene::LightType::Projected;
    l.origin = {pos(rng), pos(rng), 300.0f};
    l.target = {0, 0, -400};
    l.right = {0, -250, 0};
    l.up = {250, 0, 0};
    l.color = {colour(rng), colour(rng), colour(rng)};
    s.lights.push_back(l);
  }
  return s;
}

void add_emissive_panel(scene::Scene& s) {
  scene::Material panel;
  panel.name = "panel";
  panel.diffuse_color = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
  panel.emitter = true;
  panel.emissive_color = glm::vec4(4.0f, 3.5f, 3.0f, 1.0f);
  s.materials.push_back(panel);
  scene::Mesh lamp;
  lamp.name = "_area1";
  add_quad(lamp, int(s.materials.size() - 1), {-60, -60, 150}, {-60, 60, 150}, {60, 60, 150}, {60, -60, 150},
           {0, 0, -1});
  add_world_mesh(s, std::move(lamp));
}

scene::Scene many_lights_floor_under_a_panel(int point_lights, int projected_lights) {
  scene::Scene floor = many_lights_floor(point_lights, projected_lights);
  add_emissive_panel(floor);
  return floor;
}

}  // namespace cohort::test
