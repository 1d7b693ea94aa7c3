// The light tree and the light volumes it is built over: every light's box holds every point it lights
// (checked against the kernel's own k_light_radiance_at), every light is one leaf, every node's box
// holds its children's, the tree is as shallow as median splits make it; lights with a defect are named.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <iostream>
#include <limits>
#include <random>
#include <set>

#include "cohort/core/gpu_scene.h"
#include "cohort/core/light_sampling.h"
#include "cohort/kernel/light_tree.h"
#include "cohort/kernel/lights.h"
#include "cohort/scene/map_loader.h"
#include "cohort/scene/vfs.h"

using namespace cohort;

namespace {

scene::Light point_light(glm::vec3 origin, glm::vec3 radius) {
  scene::Light l;
  l.name = "point";
  l.origin = origin;
  l.radius = radius;
  return l;
}

scene::Light projected_light(glm::vec3 origin, glm::vec3 target, glm::vec3 right, glm::vec3 up) {
  scene::Light l;
  l.name = "projected";
  l.type = scene::LightType::Projected;
  l.origin = origin;
  l.target = target;
  l.right = right;
  l.up = up;
  return l;
}

glm::mat3 rotation(float yaw, float pitch) {
  const float cy = std::cos(yaw), sy = std::sin(yaw), cp = std::cos(pitch), sp = std::sin(pitch);
  glm::mat3 z(cy, sy, 0, -sy, cy, 0, 0, 0, 1);
  glm::mat3 y(cp, 0, -sp, 0, 1, 0, sp, 0, cp);
  return z * y;
}

bool inside(const core::LightBounds& b, KVec3 p) {
  return p.x >= b.min.x && p.x <= b.max.x && p.y >= b.min.y && p.y <= b.max.y && p.z >= b.min.z && p.z <= b.max.z;
}

// Points where the light is nonzero, found by sampling a region around it, all lie in its box; and the
// box is not much larger than the lit region (a box holding the whole world would pass the first check).
void expect_box_holds_lit_points(const scene::Light& light, float region) {
  const scene::Scene empty;
  const KLight k = core::to_klight(light, empty);
  std::optional<core::LightBounds> box = core::light_bounds(k);
  ASSERT_TRUE(box) << light.name;
  const KSceneView view{};
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-region, region);
  glm::vec3 lit_lo(INFINITY), lit_hi(-INFINITY);
  int lit = 0;
  for (int i = 0; i < 200000; ++i) {
    const KVec3 p = v3(light.origin.x + u(rng), light.origin.y + u(rng), light.origin.z + u(rng));
    if (v3_max_component(k_light_radiance_at(&view, &k, p)) <= 0.0f) continue;
    ++lit;
    ASSERT_TRUE(inside(*box, p)) << light.name << ": lit point (" << p.x << " " << p.y << " " << p.z
                                 << ") outside its box";
    lit_lo = glm::min(lit_lo, glm::vec3(p.x, p.y, p.z));
    lit_hi = glm::max(lit_hi, glm::vec3(p.x, p.y, p.z));
  }
  ASSERT_GT(lit, 100) << light.name << ": the sampled region should reach into the light";
  const glm::vec3 box_size = box->max - box->min, lit_size = lit_hi - lit_lo;
  for (int a = 0; a < 3; ++a) EXPECT_LT(box_size[a], 1.6f * lit_size[a] + 1.0f) << light.name << " axis " << a;
}

}  // namespace

TEST(LightBounds, BoxesHoldEveryLitPoint) {
  expect_box_holds_lit_points(point_light({10, 20, 30}, {100, 60, 40}), 150.0f);
  scene::Light rotated = point_light({-50, 0, 80}, {120, 30, 60});
  rotated.axis = rotation(0.6f, 0.3f);
  rotated.name = "rotated point";
  expect_box_holds_lit_points(rotated, 150.0f);
  scene::Light parallel = point_light({0, 0, 0}, {80, 80, 200});
  parallel.type = scene::LightType::Parallel;
  parallel.center = {0, 0, 1};
  parallel.name = "parallel";
  expect_box_holds_lit_points(parallel, 220.0f);
  expect_box_holds_lit_points(projected_light({0, 0, 200}, {0, 0, -256}, {0, -128, 0}, {128, 0, 0}), 400.0f);
  scene::Light turned = projected_light({30, -20, 100}, {50, 40, -200}, {0, -64, 0}, {80, 0, 20});
  turned.axis = rotation(1.1f, -0.2f);
  turned.name = "turned projected";
  expect_box_holds_lit_points(turned, 400.0f);
  scene::Light start_end = projected_light({0, 0, 0}, {256, 0, 0}, {0, -96, 0}, {0, 0, 96});
  start_end.has_start_end = true;
  start_end.start = {64, 0, 0};
  start_end.end = {300, 0, 0};
  start_end.name = "projected with light_start/light_end";
  expect_box_holds_lit_points(start_end, 400.0f);
}

TEST(LightTree, EveryLightIsOneLeafAndBoxesNest) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> pos(-2000.0f, 2000.0f), size(20.0f, 400.0f), colour(0.1f, 2.0f);
  std::vector<KLight> lights;
  const scene::Scene empty;
  for (int i = 0; i < 300; ++i) {
    scene::Light l = i % 5 == 0 ? projected_light({pos(rng), pos(rng), pos(rng)}, {0, 0, -size(rng)},
                                                   {0, -size(rng), 0}, {size(rng), 0, 0})
                                : point_light({pos(rng), pos(rng), pos(rng)}, {size(rng), size(rng), size(rng)});
    l.color = {colour(rng), colour(rng), colour(rng)};
    lights.push_back(core::to_klight(l, empty));
  }
  const std::vector<KLightNode> tree = core::build_light_tree(lights);
  ASSERT_EQ(tree.size(), 2 * lights.size() - 1);
  std::multiset<uint32_t> leaves;
  int deepest = 0;
  std::function<void(uint32_t, int)> visit = [&](uint32_t index, int depth) {
    ASSERT_LT(index, tree.size());
    const KLightNode& n = tree[index];
    deepest = std::max(deepest, depth);
    if (n.count == 1) {
      ASSERT_LT(n.left_first, lights.size());
      leaves.insert(n.left_first);
      EXPECT_EQ(n.light_count, 1u);
      std::optional<core::LightBounds> box = core::light_bounds(lights[n.left_first]);
      ASSERT_TRUE(box);
      for (int a = 0; a < 3; ++a) {
        EXPECT_LE(n.bmin[a], box->min[a]);
        EXPECT_GE(n.bmax[a], box->max[a]);
      }
      EXPECT_NEAR(n.power, v3_luminance(v3_load(lights[n.left_first].color)), 1e-5f);
      const glm::vec3 half = 0.5f * (box->max - box->min);
      EXPECT_FLOAT_EQ(n.reach, std::max(half.x, std::max(half.y, half.z)));
      return;
    }
    ASSERT_EQ(n.count, 0u);
    const KLightNode& l = tree.at(n.left_first);
    const KLightNode& r = tree.at(n.left_first + 1);
    for (int a = 0; a < 3; ++a) {
      EXPECT_LE(n.bmin[a], std::min(l.bmin[a], r.bmin[a]));
      EXPECT_GE(n.bmax[a], std::max(l.bmax[a], r.bmax[a]));
    }
    EXPECT_EQ(n.light_count, l.light_count + r.light_count);
    EXPECT_EQ(n.reach, std::max(l.reach, r.reach));
    EXPECT_NEAR(n.power, l.power + r.power, 1e-4f * n.power);
    // Median splits: the two halves differ by at most one light (the kernel's gather stack relies on it).
    EXPECT_LE(std::max(l.light_count, r.light_count) - std::min(l.light_count, r.light_count), 1u);
    visit(n.left_first, depth + 1);
    visit(n.left_first + 1, depth + 1);
  };
  visit(0, 0);
  EXPECT_EQ(leaves.size(), lights.size());
  EXPECT_EQ(std::set<uint32_t>(leaves.begin(), leaves.end()).size(), lights.size()) << "a light is in two leaves";
  EXPECT_EQ(deepest, int(std::ceil(std::log2(double(lights.size())))));
  EXPECT_EQ(core::build_light_tree(lights).size(), tree.size());
  EXPECT_EQ(std::memcmp(core::build_light_tree(lights).data(), tree.data(), tree.size() * sizeof(KLightNode)), 0)
      << "the build must be deterministic";
}

// K_LIGHTS_DENSE's descent weighs a node by k_light_node_guess: above zero wherever the node's box holds the
// point (or a light reaching it could never be picked: bias), zero elsewhere, whatever the normal; and, in a
// row of equal point lights, larger for the light whose centre is nearer (what makes it better than the
// tree's power-only importance).
TEST(LightTree, GuessIsPositiveExactlyWhereTheBoxHoldsThePoint) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> pos(-600.0f, 600.0f), size(20.0f, 400.0f), unit(-1.0f, 1.0f);
  std::vector<KLight> lights;
  const scene::Scene empty;
  for (int i = 0; i < 64; ++i) {
    scene::Light l = i % 4 == 0 ? projected_light({pos(rng), pos(rng), pos(rng)}, {0, 0, -size(rng)},
                                                   {0, -size(rng), 0}, {size(rng), 0, 0})
                                : point_light({pos(rng), pos(rng), pos(rng)}, {size(rng), size(rng), size(rng)});
    lights.push_back(core::to_klight(l, empty));
  }
  const std::vector<KLightNode> tree = core::build_light_tree(lights);
  int held = 0;
  for (int i = 0; i < 2000; ++i) {
    const KVec3 p = v3(pos(rng), pos(rng), pos(rng));
    const KVec3 normal = v3_normalize(v3(unit(rng), unit(rng), unit(rng)));
    for (const KLightNode& n : tree) {
      const float g = k_light_node_guess(&n, p, normal);
      if (k_light_node_holds(&n, p)) {
        ++held;
        ASSERT_GT(g, 0.0f) << "point " << p.x << " " << p.y << " " << p.z;
        ASSERT_TRUE(std::isfinite(g));
      } else {
        ASSERT_EQ(g, 0.0f);
      }
    }
  }
  EXPECT_GT(held, 10000) << "the points must fall in many boxes";

  std::vector<KLight> row;
  for (int i = 0; i < 2; ++i)
    row.push_back(core::to_klight(point_light({float(i) * 200.0f, 0.0f, 100.0f}, {400, 400, 400}), empty));
  const std::vector<KLightNode> pair = core::build_light_tree(row);
  ASSERT_EQ(pair.size(), 3u);
  const KLightNode& a = pair[pair[0].left_first];
  const KLightNode& b = pair[pair[0].left_first + 1];
  const KLightNode& near = a.bmin[0] < b.bmin[0] ? a : b;
  const KLightNode& far = a.bmin[0] < b.bmin[0] ? b : a;
  const KVec3 floor_point = v3(-50.0f, 0.0f, 0.0f), up = v3(0.0f, 0.0f, 1.0f);
  EXPECT_GT(k_light_node_guess(&near, floor_point, up), 2.0f * k_light_node_guess(&far, floor_point, up));
  EXPECT_EQ(k_light_node_importance(&near, floor_point), k_light_node_importance(&far, floor_point))
      << "the tree's importance cannot tell them apart";
}

// core::light_density counts, per light, the lights whose box holds its box's centre (itself included), and
// K_LIGHTS_AUTO follows it: in-range on the test map's few overlapping lights, dense in a room under a grid of
// 16 x 16 lights each reaching several rows around it (bench_scaling's kind of room); any other mode is kept.
TEST(LightDensity, CountsTheBoxesHoldingEachLightsCentreAndPicksTheAutoMode) {
  const scene::Scene empty;
  commit::TracerScene apart;
  for (int i = 0; i < 3; ++i) apart.lights.push_back(core::to_klight(point_light({i * 500.0f, 0, 0}, {100, 100, 100}), empty));
  apart.light_nodes = core::build_light_tree(apart.lights);
  EXPECT_FLOAT_EQ(core::light_density(apart), 1.0f) << "three lights apart: each holds only its own centre";
  // A large light whose box holds a small one's centre, but not the other way round: (2 + 1) / 2.
  commit::TracerScene nested;
  nested.lights = {core::to_klight(point_light({0, 0, 0}, {1000, 1000, 1000}), empty),
                   core::to_klight(point_light({600, 0, 0}, {50, 50, 50}), empty)};
  nested.light_nodes = core::build_light_tree(nested.lights);
  EXPECT_FLOAT_EQ(core::light_density(nested), 1.5f);
  EXPECT_EQ(core::light_density(commit::TracerScene{}), 0.0f);

  scene::Vfs vfs;
  const core::CompiledScene map =
      core::compile_scene(scene::load_map(vfs, std::string(COHORT_SOURCE_DIR) + "/assets/testmap/maps/testmap.map"));
  const float map_density = core::light_density(map.tracer_scene);
  commit::TracerScene grid;
  for (int x = 0; x < 16; ++x)
    for (int y = 0; y < 16; ++y)
      grid.lights.push_back(core::to_klight(point_light({x * 100.0f, y * 100.0f, 200.0f}, {350, 350, 300}), empty));
  grid.light_nodes = core::build_light_tree(grid.lights);
  const float grid_density = core::light_density(grid);
  std::cout << "light density: test map " << map_density << ", 256-light grid " << grid_density << "\n";
  EXPECT_GT(map_density, 1.0f) << "some of the test map's lights overlap";
  EXPECT_EQ(core::resolve_light_sampling(K_LIGHTS_AUTO, map_density), K_LIGHTS_IN_RANGE);
  EXPECT_EQ(core::resolve_light_sampling(K_LIGHTS_AUTO, grid_density), K_LIGHTS_DENSE);
  for (kuint mode : {K_LIGHTS_TREE, K_LIGHTS_ALL, K_LIGHTS_EVERY, K_LIGHTS_GATHER, K_LIGHTS_IN_RANGE, K_LIGHTS_DENSE})
    EXPECT_EQ(core::resolve_light_sampling(mode, grid_density), mode);
}

TEST(LightTree, LightsWithoutAVolumeAreLeftOut) {
  const scene::Scene empty;
  std::vector<KLight> lights = {core::to_klight(point_light({0, 0, 0}, {100, 100, 100}), empty),
                                core::to_klight(point_light({500, 0, 0}, {100, 100, 100}), empty)};
  lights[1].plane_s[0] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_FALSE(core::light_bounds(lights[1]));
  const std::vector<KLightNode> tree = core::build_light_tree(lights);
  ASSERT_EQ(tree.size(), 1u);
  EXPECT_EQ(tree[0].left_first, 0u);
  EXPECT_TRUE(core::build_light_tree({}).empty());
}

TEST(LightDefects, NameWhatMakesALightUnusable) {
  const scene::Scene empty;
  EXPECT_FALSE(core::light_defect(point_light({0, 0, 0}, {100, 100, 100}), empty));
  EXPECT_FALSE(core::light_defect(projected_light({0, 0, 0}, {0, 0, -256}, {0, -128, 0}, {128, 0, 0}), empty));
  auto defect = [&](const scene::Light& l) { return core::light_defect(l, empty).value_or(""); };
  EXPECT_NE(defect(point_light({0, 0, 0}, {0, 100, 100})).find("light_radius"), std::string::npos);
  EXPECT_NE(defect(point_light({0, 0, 0}, {100, -5, 100})).find("light_radius"), std::string::npos);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  EXPECT_NE(defect(point_light({nan, 0, 0}, {100, 100, 100})).find("origin"), std::string::npos);
  EXPECT_NE(defect(point_light({0, 0, 1e9f}, {100, 100, 100})).find("origin"), std::string::npos);
  EXPECT_NE(defect(point_light({0, 0, 0}, {INFINITY, 100, 100})).find("light_radius"), std::string::npos);
  EXPECT_NE(defect(projected_light({0, 0, 0}, {0, 0, -256}, {0, 0, 0}, {128, 0, 0})).find("zero vector"),
            std::string::npos);
  EXPECT_NE(defect(projected_light({0, 0, 0}, {0, 0, -256}, {128, 0, 0}, {64, 0, 0})).find("parallel"),
            std::string::npos);
  EXPECT_NE(defect(projected_light({0, 0, 0}, {0, 100, 0}, {0, -128, 0}, {128, 0, 0})).find("light_target"),
            std::string::npos);
  scene::Light open_slab = projected_light({0, 0, 0}, {0, 0, -256}, {0, -128, 0}, {128, 0, 0});
  open_slab.has_start_end = true;
  open_slab.start = {0, 0, 0};
  open_slab.end = {300, 0, 0};  // falloff across the frustum, not along it: the volume never closes
  EXPECT_NE(defect(open_slab).find("volume"), std::string::npos);
}
