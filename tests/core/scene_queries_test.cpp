#include <gtest/gtest.h>

#include "cohort/core/gpu_scene.h"
#include "cohort/core/scene_queries.h"

using namespace cohort;

namespace {

// A floor quad (world) and a wall quad owned by entity 0 standing on it at x = 0.
scene::Scene wall_on_floor(bool wall_casts_shadows) {
  scene::Scene s;
  s.materials.push_back(scene::Material{});
  s.materials[0].name = "plain";
  auto quad = [](scene::Mesh& m, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d) {
    uint32_t base = uint32_t(m.vertices.size());
    for (glm::vec3 p : {a, b, c, d}) {
      scene::Vertex v;
      v.position = p;
      m.vertices.push_back(v);
    }
    for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) m.indices.push_back(base + i);
    m.surfaces.push_back({0, uint32_t(m.indices.size() - 6), 6});
  };
  scene::Mesh floor;
  floor.name = "_area0";
  quad(floor, {-100, -100, 0}, {100, -100, 0}, {100, 100, 0}, {-100, 100, 0});
  s.meshes.push_back(floor);
  s.area_meshes.push_back(0);
  scene::Mesh wall;
  wall.name = "wall";
  quad(wall, {0, -50, 0}, {0, 50, 0}, {0, 50, 80}, {0, -50, 80});
  s.meshes.push_back(wall);
  scene::Entity e;
  e.name = "wall_1";
  e.classname = "func_static";
  e.mesh = 1;
  e.origin = glm::vec3(10, 0, 0);
  e.no_shadows = !wall_casts_shadows;
  s.entities.push_back(e);
  return s;
}

}  // namespace

TEST(SceneQueries, LineOfSightIsBlockedByTheEntityWall) {
  auto compiled = core::compile_scene(wall_on_floor(true));
  core::SceneQueries q(std::make_shared<commit::TracerScene>(compiled.tracer_scene));
  EXPECT_FALSE(q.line_of_sight({-50, 0, 40}, {50, 0, 40}));   // through the wall (at x = 10)
  EXPECT_TRUE(q.line_of_sight({-50, 0, 40}, {-50, 60, 40}));   // beside it
  EXPECT_TRUE(q.line_of_sight({-50, 0, 100}, {50, 0, 100}));   // over it
  EXPECT_TRUE(q.line_of_sight({-50, 0, 40}, {-50, 0, 40}));    // a point sees itself
}

TEST(SceneQueries, PickReturnsTheNearestSurfaceAndItsEntity) {
  scene::Scene s = wall_on_floor(true);
  auto compiled = core::compile_scene(s);
  core::SceneQueries q(std::make_shared<commit::TracerScene>(compiled.tracer_scene));
  auto wall = q.pick({-50, 0, 40}, {1, 0, 0});
  ASSERT_TRUE(wall.has_value());
  EXPECT_NEAR(wall->distance, 60.0f, 1e-3f);
  EXPECT_NEAR(wall->point.x, 10.0f, 1e-3f);
  EXPECT_EQ(wall->entity, 0u);
  auto floor = q.pick({-50, 0, 40}, {0, 0, -2});
  ASSERT_TRUE(floor.has_value());
  EXPECT_NEAR(floor->distance, 40.0f, 1e-3f);
  EXPECT_EQ(floor->entity, K_NONE);
  EXPECT_FALSE(q.pick({-50, 0, 40}, {0, 0, 1}).has_value());   // the sky
  EXPECT_FALSE(q.pick({-50, 0, 40}, {1, 0, 0}, 30.0f).has_value());   // out of reach
}

TEST(SceneQueries, NoShadowsEntitiesDoNotBlockLineOfSight) {
  auto compiled = core::compile_scene(wall_on_floor(false));
  core::SceneQueries q(std::make_shared<commit::TracerScene>(compiled.tracer_scene));
  EXPECT_TRUE(q.line_of_sight({-50, 0, 40}, {50, 0, 40}));
  EXPECT_TRUE(q.pick({-50, 0, 40}, {1, 0, 0}).has_value()) << "still visible, so still pickable";
}
