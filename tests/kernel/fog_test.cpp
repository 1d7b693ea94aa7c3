// Fog and blend light volumes in the kernel, compiled as plain C++: the fog opacity against the
// engine's `_fog` table formula, and the clipped length of rays through box and projected volumes.
#include <gtest/gtest.h>

#include <cmath>

#include "cohort/kernel/fog.h"

namespace {

// A box light of half size r around c, axis-aligned (S, T, F = the normalised x, y, z; Q = 1).
KLight box_light(KVec3 c, KVec3 r) {
  KLight l{};
  const float cc[3] = {c.x, c.y, c.z}, rr[3] = {r.x, r.y, r.z};
  float* planes[3] = {l.plane_s, l.plane_t, l.plane_f};
  for (int k = 0; k < 3; ++k) {
    planes[k][k] = 0.5f / rr[k];
    planes[k][3] = 0.5f - 0.5f * cc[k] / rr[k];
  }
  l.plane_q[3] = 1.0f;
  return l;
}

}  // namespace

TEST(KernelFog, OpacityIsTheFogTable) {
  const float d = 400.0f;
  for (float len : {0.0f, 10.0f, 100.0f, 250.0f, 390.0f}) {
    double b = std::min(255.0, 255.0 * (64.0 / 63.0) * len / d);
    EXPECT_NEAR(k_fog_opacity(len, d), 1.0 - std::pow(0.982, b), 1e-5) << "length " << len;
  }
  EXPECT_NEAR(k_fog_opacity(d, d), 0.99, 0.001) << "about 0.99 at the fog distance";
  EXPECT_EQ(k_fog_opacity(d + 1.0f, d), 1.0f) << "opaque beyond it";
  EXPECT_EQ(k_fog_opacity(-5.0f, d), 0.0f);
}

TEST(KernelFog, RayLengthInsideABoxVolume) {
  KLight l = box_light(v3(10, 20, 30), v3(50, 40, 30));
  // Along +x through the centre (x from -40 to 60): the full 100 units; stopped at x = 10 by tmax.
  EXPECT_NEAR(k_light_volume_length(&l, v3(-100, 20, 30), v3(1, 0, 0), K_INF), 100.0f, 1e-3f);
  EXPECT_NEAR(k_light_volume_length(&l, v3(-100, 20, 30), v3(1, 0, 0), 110.0f), 50.0f, 1e-3f);
  // Starting inside, going up: from z = 30 to the top at 60.
  EXPECT_NEAR(k_light_volume_length(&l, v3(10, 20, 30), v3(0, 0, 1), K_INF), 30.0f, 1e-3f);
  // A diagonal through a corner region: compare with the slab method in double precision.
  KVec3 o = v3(-70, -40, 0), d = v3_normalize(v3(1, 0.8f, 0.5f));
  double t0 = 0.0, t1 = 1e30;
  const double lo[3] = {-40, -20, 0}, hi[3] = {60, 60, 60}, oo[3] = {o.x, o.y, o.z}, dd[3] = {d.x, d.y, d.z};
  for (int k = 0; k < 3; ++k) {
    double a = (lo[k] - oo[k]) / dd[k], b = (hi[k] - oo[k]) / dd[k];
    t0 = std::max(t0, std::min(a, b));
    t1 = std::min(t1, std::max(a, b));
  }
  ASSERT_GT(t1, t0);
  EXPECT_NEAR(k_light_volume_length(&l, o, d, K_INF), t1 - t0, 1e-3);
  // Missing it, and parallel to a face outside it.
  EXPECT_EQ(k_light_volume_length(&l, v3(-100, 100, 30), v3(1, 0, 0), K_INF), 0.0f);
  EXPECT_EQ(k_light_volume_length(&l, v3(-100, 20, 61), v3(1, 0, 0), K_INF), 0.0f);
  EXPECT_TRUE(k_light_volume_contains(&l, v3(10, 20, 30)));
  EXPECT_FALSE(k_light_volume_contains(&l, v3(10, 20, 61)));
}

// A projected volume, the pyramid 0 <= S, T <= Q from the apex at the origin looking down +z
// (S = (x + z) / 2, T = (y + z) / 2, Q = z: a 90 degree frustum), cut by 0 <= F = z / 100 <= 1.
TEST(KernelFog, RayLengthInsideAProjectedVolume) {
  KLight l{};
  l.plane_s[0] = 0.5f; l.plane_s[2] = 0.5f;
  l.plane_t[1] = 0.5f; l.plane_t[2] = 0.5f;
  l.plane_q[2] = 1.0f;
  l.plane_f[2] = 0.01f;
  // Along the axis from below: z from 0 to 100.
  EXPECT_NEAR(k_light_volume_length(&l, v3(0, 0, -50), v3(0, 0, 1), K_INF), 100.0f, 1e-3f);
  // Across at z = 50: the frustum is |x| <= 50 there.
  EXPECT_NEAR(k_light_volume_length(&l, v3(-200, 0, 50), v3(1, 0, 0), K_INF), 100.0f, 1e-3f);
  // Behind the apex: nothing.
  EXPECT_EQ(k_light_volume_length(&l, v3(-200, 0, -10), v3(1, 0, 0), K_INF), 0.0f);
}

// The box light's cheap reject (k_segment_misses_box_light) never drops a segment that has a length inside
// the volume: random boxes and segments (some starting inside, some ending short of it, some endless), every
// rejected one has length 0 by the six clips; it rejects the far ones (most here); projected lights, and box
// lights without a reach (packs from before it), never.
TEST(KernelFog, TheBoxRejectNeverDropsASegmentInsideTheVolume) {
  uint32_t state = 12345u;
  auto uniform = [&](float lo, float hi) {
    state = state * 1664525u + 1013904223u;
    return lo + (hi - lo) * float(state >> 8) / float(1u << 24);
  };
  int rejected = 0, crossing = 0;
  for (int i = 0; i < 20000; ++i) {
    const KVec3 c = v3(uniform(-500, 500), uniform(-500, 500), uniform(-100, 300));
    const KVec3 r = v3(uniform(0.0005f, 200), uniform(0.0005f, 200), uniform(0.0005f, 200));
    KLight l = box_light(c, v3(std::max(r.x, 1e-3f), std::max(r.y, 1e-3f), std::max(r.z, 1e-3f)));
    l.type = K_LIGHT_POINT;
    l.origin[0] = c.x, l.origin[1] = c.y, l.origin[2] = c.z;
    l.radius[0] = r.x, l.radius[1] = r.y, l.radius[2] = r.z;
    l.volume_reach = std::sqrt(std::max(r.x, 1e-3f) * std::max(r.x, 1e-3f) + std::max(r.y, 1e-3f) * std::max(r.y, 1e-3f) +
                               std::max(r.z, 1e-3f) * std::max(r.z, 1e-3f));
    const KVec3 o = v3(uniform(-800, 800), uniform(-800, 800), uniform(-300, 500));
    const KVec3 d = v3_normalize(v3(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)));
    const float tmax = i % 4 == 0 ? K_INF : uniform(0, 1500);
    const float length = k_light_volume_length(&l, o, d, tmax);
    const bool misses = k_segment_misses_box_light(&l, o, d, tmax) != 0;
    crossing += length > 0.0f;
    rejected += misses;
    if (misses) {
      ASSERT_EQ(length, 0.0f) << "segment " << i << " was dropped but crosses the volume";
    }
    l.type = K_LIGHT_PROJECTED;
    ASSERT_EQ(k_segment_misses_box_light(&l, o, d, tmax), 0) << "projected lights are never rejected";
    l.type = K_LIGHT_POINT;
    l.volume_reach = 0.0f;
    ASSERT_EQ(k_segment_misses_box_light(&l, o, d, tmax), 0) << "a light without a reach is never rejected";
  }
  EXPECT_GT(crossing, 100) << "some segments should cross their box";
  EXPECT_GT(rejected, 10000) << "most far segments should be rejected";
}
