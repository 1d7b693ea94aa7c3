// The Embree tracer's emissive picks eight at a time (cohort/tracers/embree_emissive_picks.h) against the
// portable k_emissive_tree_pick they stand for: the same triangle and the same probability, bit for bit (this
// file is built without FMA contraction, as the baseline tile renderers are), for trees small enough for the
// per-lane table (the test map has 10 emitters, the large map 14) and larger ones (gathered nodes), with
// a light tree before the emissive one, one emitter, numbers near 1 and 0, points inside the emitters' boxes,
// emitters without power (a node whose children have none picks nothing), and counts that leave lanes empty.
#ifdef COHORT_HAVE_EMBREE
#include "cohort/tracers/embree_emissive_picks.h"
#endif

#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <vector>

#include "cohort/core/light_sampling.h"
#include "cohort/test_support/scene_builders.h"

#ifdef COHORT_HAVE_EMBREE
using namespace cohort;

namespace {

struct Emitters {
  std::vector<KLight> lights;
  core::EmissiveList emissive;
  std::vector<KLightNode> nodes;
  KSceneView view{};
};

void store(float* dst, glm::vec3 v) {
  dst[0] = v.x;
  dst[1] = v.y;
  dst[2] = v.z;
}

// n small triangles scattered over a 4000-unit cube; powers from `power` (0: none), lights before them
// in the node array when with_lights.
void build(Emitters& s, int n, uint32_t seed, bool with_lights, float zero_power_share) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-2000.0f, 2000.0f), power(0.5f, 4.0f), unit(0.0f, 1.0f);
  for (int i = 0; i < n; ++i) {
    const glm::vec3 c(pos(rng), pos(rng), pos(rng));
    KEmissiveTriangle e{};
    store(e.p0, c);
    store(e.p1, c + glm::vec3(8, 0, 0));
    store(e.p2, c + glm::vec3(0, 8, 0));
    e.instance = uint32_t(i / 7);
    e.triangle = uint32_t(3 * i);
    s.emissive.triangles.push_back(e);
    s.emissive.power.push_back(unit(rng) < zero_power_share ? 0.0f : power(rng));
  }
  if (with_lights) {
    const KLight light = test::kernel_point_light_about_origin(100.0f);
    s.lights = {light, light, light};
  }
  s.nodes = core::build_light_nodes(s.lights, s.emissive);
  s.view.light_nodes = s.nodes.data();
  s.view.light_node_count = kuint(s.nodes.size());
  s.view.emissive = s.emissive.triangles.data();
  s.view.emissive_count = kuint(s.emissive.triangles.size());
}

uint32_t bits(float x) {
  uint32_t b;
  std::memcpy(&b, &x, sizeof b);
  return b;
}

// Picks for `count` points and numbers at once, each against the portable pick.
void expect_portable_picks(const KSceneView& view, const std::vector<KVec3>& points, const std::vector<float>& us) {
  std::vector<KEmissivePick> picks(points.size(), KEmissivePick{12345u, -1.0f});
  tracers::embree_emissive::picks(&view, int(points.size()), points.data(), us.data(), picks.data());
  for (size_t i = 0; i < points.size(); ++i) {
    float prob = 0.0f;
    const kuint index = k_emissive_tree_pick(&view, points[i], us[i], &prob);
    ASSERT_EQ(picks[i].index, index) << "point " << i << " u " << us[i];
    if (index != K_NONE) {
      EXPECT_EQ(bits(picks[i].prob), bits(prob)) << "point " << i << " u " << us[i];
    }
  }
}

// Random points (some inside emitters' boxes) and numbers (some at the ends of [0, 1)), n of each.
void random_queries(const Emitters& s, int n, uint32_t seed, std::vector<KVec3>* points, std::vector<float>* us) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-2500.0f, 2500.0f), unit(0.0f, 1.0f), near(-6.0f, 6.0f);
  const float ends[] = {0.0f, 0.99999994f, 0.9999999f, 1e-7f};
  for (int k = 0; k < n; ++k) {
    if (k % 5 == 0 && !s.emissive.triangles.empty()) {
      const KEmissiveTriangle& e = s.emissive.triangles[size_t(k) % s.emissive.triangles.size()];
      points->push_back(v3(e.p0[0] + 4.0f + near(rng), e.p0[1] + 4.0f + near(rng), e.p0[2] + near(rng)));
    } else {
      points->push_back(v3(pos(rng), pos(rng), pos(rng)));
    }
    us->push_back(k % 7 == 3 ? ends[size_t(k / 7) % 4] : unit(rng) * 0.99999994f);
  }
}

void expect_portable_picks_on(int emitters, bool with_lights, float zero_power_share, uint32_t seed) {
  Emitters s;
  build(s, emitters, seed, with_lights, zero_power_share);
  for (int n : {1, 7, 8, 9, 200, 203}) {
    std::vector<KVec3> points;
    std::vector<float> us;
    random_queries(s, n, seed * 31u + uint32_t(n), &points, &us);
    expect_portable_picks(s.view, points, us);
  }
}

}  // namespace

TEST(EmbreeEmissivePicks, MatchThePortablePickInTheTable) {
  for (int emitters : {2, 3, 10, 14, 32}) expect_portable_picks_on(emitters, false, 0.0f, uint32_t(emitters));
}

TEST(EmbreeEmissivePicks, MatchThePortablePickFromGatheredNodes) {
  ASSERT_GT(2u * 33u - 1u, tracers::embree_emissive::kTableNodes);
  for (int emitters : {33, 300}) expect_portable_picks_on(emitters, false, 0.0f, uint32_t(emitters));
}

TEST(EmbreeEmissivePicks, MatchThePortablePickBehindTheLightTree) {
  expect_portable_picks_on(10, true, 0.0f, 7u);
  expect_portable_picks_on(100, true, 0.0f, 8u);
}

TEST(EmbreeEmissivePicks, OneEmitterIsPickedWithProbabilityOne) {
  Emitters s;
  build(s, 1, 4u, false, 0.0f);
  const std::vector<KVec3> points = {v3(0, 0, 0), v3(1e6f, -1e6f, 3.0f)};
  const std::vector<float> us = {0.0f, 0.99999994f};
  std::vector<KEmissivePick> picks(2);
  tracers::embree_emissive::picks(&s.view, 2, points.data(), us.data(), picks.data());
  for (const KEmissivePick& pick : picks) {
    EXPECT_EQ(pick.index, 0u);
    EXPECT_EQ(pick.prob, 1.0f);
  }
}

TEST(EmbreeEmissivePicks, EmittersWithoutPowerPickAsThePortablePick) {
  // Some children without power, and trees where whole subtrees (or every emitter) have none: the portable
  // pick then returns K_NONE, and so must these.
  int none = 0;
  for (float share : {0.3f, 0.8f, 1.0f})
    for (int emitters : {4, 20, 80}) {
      Emitters s;
      build(s, emitters, uint32_t(emitters) + 100u, false, share);
      std::vector<KVec3> points;
      std::vector<float> us;
      random_queries(s, 64, uint32_t(emitters), &points, &us);
      expect_portable_picks(s.view, points, us);
      for (size_t i = 0; i < points.size(); ++i) {
        float prob = 0.0f;
        if (k_emissive_tree_pick(&s.view, points[i], us[i], &prob) == K_NONE) ++none;
      }
    }
  EXPECT_GT(none, 0) << "some picks should meet children without power";
}

TEST(EmbreeEmissivePicks, NoEmissiveTreePicksNothing) {
  Emitters s;
  build(s, 0, 1u, true, 0.0f);
  const KVec3 p = v3(0, 0, 0);
  const float u = 0.5f;
  KEmissivePick pick{0u, 1.0f};
  tracers::embree_emissive::picks(&s.view, 1, &p, &u, &pick);
  EXPECT_EQ(pick.index, K_NONE);
}
#endif
