// The emissive tree (kernel/emissive_tree.h over core's build_light_nodes): the pick probabilities at a
// point sum to one, the probability reported with a pick equals k_emissive_tree_pdf for that triangle,
// picks follow those probabilities, near emitters are picked more often than far ones of the same power,
// and every (instance, triangle) is found by k_emissive_find.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "cohort/core/light_sampling.h"
#include "cohort/test_support/scene_builders.h"
#include "cohort/kernel/emissive_tree.h"

using namespace cohort;

namespace {

struct Sources {
  std::vector<KLight> lights;  // none: the emissive tree then starts at node 0
  core::EmissiveList emissive;
  std::vector<KLightNode> nodes;
};

void store(float* dst, glm::vec3 v) {
  dst[0] = v.x;
  dst[1] = v.y;
  dst[2] = v.z;
}

// n small triangles scattered over a 4000-unit cube, instance = i / 7, triangle = 3 i (sorted).
Sources scattered_emitters(int n, uint32_t seed) {
  Sources s;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-2000.0f, 2000.0f), power(0.5f, 4.0f);
  for (int i = 0; i < n; ++i) {
    const glm::vec3 c(pos(rng), pos(rng), pos(rng));
    KEmissiveTriangle e{};
    store(e.p0, c);
    store(e.p1, c + glm::vec3(8, 0, 0));
    store(e.p2, c + glm::vec3(0, 8, 0));
    e.instance = uint32_t(i / 7);
    e.triangle = uint32_t(3 * i);
    s.emissive.triangles.push_back(e);
    s.emissive.power.push_back(power(rng));
  }
  s.nodes = core::build_light_nodes(s.lights, s.emissive);
  return s;
}

KSceneView view_of(const Sources& s) {
  KSceneView v{};
  v.light_nodes = s.nodes.data();
  v.light_node_count = kuint(s.nodes.size());
  v.emissive = s.emissive.triangles.data();
  v.emissive_count = kuint(s.emissive.triangles.size());
  return v;
}

}  // namespace

TEST(EmissiveTree, ProbabilitiesSumToOneAndMatchPicks) {
  const Sources s = scattered_emitters(300, 11);
  ASSERT_EQ(s.nodes.size(), 2 * s.emissive.triangles.size() - 1);
  const KSceneView view = view_of(s);
  ASSERT_EQ(k_emissive_root(&view), 0u);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> pos(-2500.0f, 2500.0f), unit(0.0f, 1.0f);
  for (int trial = 0; trial < 8; ++trial) {
    const KVec3 p = v3(pos(rng), pos(rng), pos(rng));
    double sum = 0.0;
    for (kuint i = 0; i < view.emissive_count; ++i) {
      const float pdf = k_emissive_tree_pdf(&view, p, i);
      EXPECT_GT(pdf, 0.0f) << "every emitter must keep a nonzero probability";
      sum += pdf;
    }
    EXPECT_NEAR(sum, 1.0, 1e-4);
    for (int k = 0; k < 50; ++k) {
      float pick = 0.0f;
      const kuint i = k_emissive_tree_pick(&view, p, unit(rng) * 0.99999994f, &pick);
      ASSERT_LT(i, view.emissive_count);
      EXPECT_NEAR(pick, k_emissive_tree_pdf(&view, p, i), 1e-5f * std::max(1.0f, pick));
    }
  }
}

TEST(EmissiveTree, PicksFollowTheProbabilities) {
  const Sources s = scattered_emitters(24, 3);
  const KSceneView view = view_of(s);
  const KVec3 p = v3(100.0f, -300.0f, 50.0f);
  std::vector<int> hits(view.emissive_count, 0);
  const int draws = 200000;
  for (int k = 0; k < draws; ++k) {
    float pick = 0.0f;
    const kuint i = k_emissive_tree_pick(&view, p, (float(k) + 0.5f) / float(draws), &pick);
    ASSERT_LT(i, view.emissive_count);
    ++hits[i];
  }
  for (kuint i = 0; i < view.emissive_count; ++i) {
    const double expected = k_emissive_tree_pdf(&view, p, i) * draws;
    // Stratified u: the count is within one stratum per tree level of the expectation, plus rounding.
    EXPECT_NEAR(hits[i], expected, 2.0 + 0.002 * draws) << "emitter " << i;
  }
}

TEST(EmissiveTree, NearEmittersArePickedMoreOften) {
  Sources s;
  for (int i = 0; i < 64; ++i) {
    KEmissiveTriangle e{};
    const glm::vec3 c(float(i) * 200.0f, 0.0f, 0.0f);
    store(e.p0, c);
    store(e.p1, c + glm::vec3(10, 0, 0));
    store(e.p2, c + glm::vec3(0, 10, 0));
    e.instance = 0;
    e.triangle = uint32_t(i);
    s.emissive.triangles.push_back(e);
    s.emissive.power.push_back(1.0f);
  }
  s.nodes = core::build_light_nodes(s.lights, s.emissive);
  const KSceneView view = view_of(s);
  const KVec3 near_first = v3(0.0f, 0.0f, 50.0f);
  EXPECT_GT(k_emissive_tree_pdf(&view, near_first, 0), 20.0f * k_emissive_tree_pdf(&view, near_first, 63));
  const KVec3 near_last = v3(63.0f * 200.0f, 0.0f, 50.0f);
  EXPECT_GT(k_emissive_tree_pdf(&view, near_last, 63), 20.0f * k_emissive_tree_pdf(&view, near_last, 0));
}

TEST(EmissiveTree, EveryTriangleIsFoundAndOthersAreNot) {
  const Sources s = scattered_emitters(100, 9);
  const KSceneView view = view_of(s);
  for (kuint i = 0; i < view.emissive_count; ++i) {
    EXPECT_EQ(k_emissive_find(&view, s.emissive.triangles[i].instance, s.emissive.triangles[i].triangle), i);
    EXPECT_EQ(k_emissive_find(&view, s.emissive.triangles[i].instance, s.emissive.triangles[i].triangle + 1), K_NONE);
    const KLightNode& leaf = s.nodes.at(s.emissive.triangles[i].leaf);
    EXPECT_EQ(leaf.count, 1u);
    EXPECT_EQ(leaf.left_first, i);
  }
  EXPECT_EQ(k_emissive_find(&view, 1000, 0), K_NONE);
}

TEST(EmissiveTree, FollowsTheLightTreeInTheNodeArray) {
  Sources s = scattered_emitters(10, 2);
  // A point light's box comes from its S, T, F planes: the cube of radius 100 about the origin.
  const KLight light = test::kernel_point_light_about_origin(100.0f);
  s.lights = {light, light, light};
  s.nodes = core::build_light_nodes(s.lights, s.emissive);
  const size_t light_nodes = core::build_light_tree(s.lights).size();
  ASSERT_EQ(light_nodes, 5u);
  ASSERT_EQ(s.nodes.size(), light_nodes + 2 * 10 - 1);
  const KSceneView view = view_of(s);
  EXPECT_EQ(k_emissive_root(&view), kuint(light_nodes));
  EXPECT_EQ(s.nodes[light_nodes].parent, K_NONE);
  EXPECT_EQ(s.nodes[0].parent, K_NONE);
  double sum = 0.0;
  for (kuint i = 0; i < view.emissive_count; ++i) sum += k_emissive_tree_pdf(&view, v3(0, 0, 0), i);
  EXPECT_NEAR(sum, 1.0, 1e-5);
}
