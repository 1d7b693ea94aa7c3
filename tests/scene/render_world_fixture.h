// Test helper: a small scene in the shape of the test map (a door, a fan, a flickering light), built in
// memory so the RenderWorld and stream tests need no files.
#pragma once

#include <string>

#include "cohort/scene/render_world.h"
#include "cohort/scene/scene.h"

namespace cohort::scene::world_testing {

inline Mesh box_mesh(const std::string& name, glm::vec3 half, int material) {
  Mesh m;
  m.name = name;
  for (int i = 0; i < 8; ++i) {
    Vertex v;
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

inline Image checker(const std::string& name, int size) {
  Image img;
  img.name = name;
  img.width = img.height = size;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x)
      for (int c = 0; c < 4; ++c) img.rgba.push_back(uint8_t(((x + y) & 1) ? 255 : 40 * c));
  return img;
}

inline Scene small_map() {
  Scene s;
  s.name = "small";
  s.images.push_back(checker("textures/test/checker", 4));
  Material floor;
  floor.name = "textures/test/floor";
  floor.diffuse_image = 0;
  s.materials.push_back(floor);
  Material light_shader;
  light_shader.name = "lights/test/flicker";
  light_shader.is_light_material = true;
  s.materials.push_back(light_shader);
  s.meshes.push_back(box_mesh("_area0", {512, 512, 8}, 0));
  s.area_meshes.push_back(0);
  s.meshes.push_back(box_mesh("door_main", {4, 32, 48}, 0));
  s.meshes.push_back(box_mesh("fan_spin", {32, 32, 2}, 0));
  Entity player;
  player.name = "info_player_start_1";
  player.classname = "info_player_start";
  s.entities.push_back(player);
  Entity door;
  door.name = "door_main";
  door.classname = "func_door";
  door.mesh = 1;
  door.origin = {128, 0, 48};
  s.entities.push_back(door);
  Entity fan;
  fan.name = "fan_spin";
  fan.classname = "func_rotating";
  fan.mesh = 2;
  fan.origin = {0, 128, 120};
  s.entities.push_back(fan);
  Light flicker;
  flicker.name = "light_flicker";
  flicker.origin = {0, 0, 100};
  flicker.color = {1.0f, 0.8f, 0.6f};
  flicker.material = 1;
  s.lights.push_back(flicker);
  Light fill;
  fill.name = "light_fill";
  fill.origin = {-200, 0, 100};
  fill.radius = glm::vec3(500.0f);
  s.lights.push_back(fill);
  s.player_start = {-100, 0, 40};
  return s;
}

}  // namespace cohort::scene::world_testing
