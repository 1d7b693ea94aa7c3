// The Embree tracer's SSE box test for light tree nodes (K_LIGHT_NODE_HOLDS, cohort/tracers/embree_light_box.h)
// against the portable test it replaces: random boxes and points, points on every face and corner, flat and
// inverted boxes, infinite and NaN coordinates.
#ifdef COHORT_HAVE_EMBREE
#include "cohort/tracers/embree_light_box.h"  // first: k_light_node_holds below tests through the hook
#endif
#include "cohort/kernel/light_tree.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#ifdef K_LIGHT_NODE_HOLDS
namespace {

// light_tree.h's test without the hook.
int portable_holds(const KLightNode& n, KVec3 p) {
  return p.x >= n.bmin[0] && p.x <= n.bmax[0] && p.y >= n.bmin[1] && p.y <= n.bmax[1] && p.z >= n.bmin[2] &&
         p.z <= n.bmax[2];
}

KLightNode box(float x0, float y0, float z0, float x1, float y1, float z1) {
  KLightNode n{};
  n.bmin[0] = x0, n.bmin[1] = y0, n.bmin[2] = z0;
  n.bmax[0] = x1, n.bmax[1] = y1, n.bmax[2] = z1;
  n.left_first = 0xFFFFFFFFu;  // a NaN's bits in the lane the test must not compare
  n.count = 0x7FC00000u;
  return n;
}

}  // namespace

TEST(EmbreeLightBox, SseTestMatchesThePortableTest) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> coord(-100.0f, 100.0f);
  int inside = 0, cases = 0;
  for (int b = 0; b < 2000; ++b) {
    float lo[3], hi[3];
    for (int k = 0; k < 3; ++k) {
      lo[k] = coord(rng);
      hi[k] = b % 10 == 0 ? lo[k] : b % 17 == 0 ? lo[k] - 1.0f : lo[k] + std::fabs(coord(rng));  // flat, inverted
    }
    const KLightNode n = box(lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
    std::vector<KVec3> points;
    for (int k = 0; k < 8; ++k) points.push_back(v3(coord(rng), coord(rng), coord(rng)));
    for (int c = 0; c < 8; ++c)  // corners, and points on the faces
      points.push_back(v3(c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1], c & 4 ? hi[2] : lo[2]));
    points.push_back(v3(lo[0], 0.5f * (lo[1] + hi[1]), 0.5f * (lo[2] + hi[2])));
    points.push_back(v3(0.5f * (lo[0] + hi[0]), 0.5f * (lo[1] + hi[1]), std::nextafter(hi[2], 1e30f)));
    for (const KVec3& p : points) {
      ASSERT_EQ(k_light_node_holds(&n, p), portable_holds(n, p)) << "box " << b;
      inside += portable_holds(n, p);
      ++cases;
    }
  }
  EXPECT_GT(inside, cases / 10) << "the cases should hold points inside as well as outside";
  EXPECT_LT(inside, cases);
}

TEST(EmbreeLightBox, InfiniteAndNanCoordinates) {
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  const KLightNode everywhere = box(-inf, -inf, -inf, inf, inf, inf), unit = box(0, 0, 0, 1, 1, 1);
  const KVec3 points[] = {v3(0, 0, 0), v3(inf, 0, 0), v3(0, -inf, 0.5f), v3(nan, 0.5f, 0.5f), v3(0.5f, 0.5f, nan)};
  for (const KVec3& p : points) {
    EXPECT_EQ(k_light_node_holds(&everywhere, p), portable_holds(everywhere, p));
    EXPECT_EQ(k_light_node_holds(&unit, p), portable_holds(unit, p));
  }
  EXPECT_TRUE(k_light_node_holds(&everywhere, v3(inf, 0, 0)));
  EXPECT_FALSE(k_light_node_holds(&unit, v3(nan, 0.5f, 0.5f)));
}
#endif
