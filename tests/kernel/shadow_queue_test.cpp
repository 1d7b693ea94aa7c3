// The shadow queue (kernel/shadow_queue.h) compiled as plain C++ over a stand-in scene, a wall on the plane
// x = 0 that blocks every shadow ray crossing it: a vertex whose rays wait in slots and are walked later,
// as CUDA's shadow walk does (a visibility bit per ray, then the visible values in order), gets the light,
// float for float, of one whose rays are walked as they come; and a vertex gets a slot for every ray it
// can emit, or none.
#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <vector>

#include "cohort/kernel/layout.h"
#include "cohort/kernel/scene_view.h"
#include "cohort/kernel/shadow_ray.h"

typedef struct KTraceCtx {
  KSceneView scene;
  unsigned occlusion_rays;
} KTraceCtx;

static int k_trace_closest(KTraceCtx*, KVec3, KVec3, float, kuint, KHit*) { return 0; }

static int k_trace_occluded(KTraceCtx* ctx, KVec3 org, KVec3 dir, float tmax, kuint mask) {
  ++ctx->occlusion_rays;
  EXPECT_EQ(mask & K_SHADOW_RAY_EMISSIVE, 0u) << "the emissive mark stays out of the walk's mask";
  const float t = -org.x / dir.x;
  return t > 0.0f && t < tmax;
}

#include "cohort/kernel/integrator.h"

namespace {

KShadowRay random_ray(std::mt19937& rng, bool emissive) {
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), positive(0.01f, 3.0f);
  KShadowRay r;
  r.org = v3(u(rng), u(rng), u(rng));
  r.dir = v3_normalize(v3(u(rng), u(rng), u(rng)));
  r.tmax = rng() % 5 == 0 ? 0.0f : positive(rng);  // some need no walk (a light without shadows)
  r.mask = K_MASK_SHADOW | (emissive ? K_SHADOW_RAY_EMISSIVE : 0u);
  r.value = v3(positive(rng), positive(rng), positive(rng));
  r.kept = emissive ? 1.0f : positive(rng);
  return r;
}

KVertexLight vertex_of(std::mt19937& rng, float direct_scale, kuint has_emissive) {
  std::uniform_real_distribution<float> positive(0.01f, 3.0f);
  KVertexLight v;
  std::memset(&v, 0, sizeof v);
  v.throughput = v3(positive(rng), positive(rng), positive(rng));
  v.clamp = rng() % 2 ? 4.0f : 0.0f;
  v.base = v3(positive(rng), positive(rng), positive(rng));
  v.direct_scale = direct_scale;
  v.has_emissive = has_emissive;
  return v;
}

}  // namespace

TEST(KernelShadowQueue, RaysWalkedLaterGiveTheLightOfRaysWalkedAsTheyCome) {
  std::mt19937 rng(7);
  int visible_some = 0, blocked_some = 0;
  for (int trial = 0; trial < 500; ++trial) {
    const kuint rays = 1u + rng() % K_SHADOW_QUEUE_MAX;
    const kuint has_emissive = rng() % 2;
    const float direct_scale = rng() % 2 ? 0.0f : 1.0f / float(1u + rng() % 3);
    std::vector<KShadowRay> emitted;
    for (kuint k = 0; k < rays; ++k) emitted.push_back(random_ray(rng, has_emissive && k + 1 == rays));
    const KVertexLight start = vertex_of(rng, direct_scale, has_emissive);

    KTraceCtx ctx_inline{}, ctx_slots{};
    KVertexLight now = start, later = start;
    KShadowQueue inline_queue = k_shadow_queue_inline();
    std::vector<KShadowRay> slots(K_SHADOW_QUEUE_MAX);
    KShadowQueue slot_queue = k_shadow_queue_inline();
    slot_queue.rays = slots.data();
    slot_queue.stride = 1u;
    slot_queue.capacity = K_SHADOW_QUEUE_MAX;
    for (const KShadowRay& r : emitted) {
      k_shadow_queue_push(&ctx_inline, &inline_queue, &now, r);
      k_shadow_queue_push(&ctx_slots, &slot_queue, &later, r);
    }
    EXPECT_EQ(inline_queue.count, 0u);
    ASSERT_EQ(slot_queue.count, rays);
    ASSERT_EQ(later.ray_count, rays);
    EXPECT_EQ(ctx_slots.occlusion_rays, 0u) << "nothing walked while the rays wait";

    kuint visible = 0u;
    for (kuint k = 0; k < later.ray_count; ++k)
      if (k_shadow_ray_visible(&ctx_slots, &slots[k])) visible |= 1u << k;
    for (kuint k = 0; k < later.ray_count; ++k)
      if (visible & (1u << k)) k_shadow_ray_add(&later, &slots[k]);
    visible_some += visible != 0u;
    blocked_some += visible != (1u << rays) - 1u;

    EXPECT_EQ(ctx_slots.occlusion_rays, ctx_inline.occlusion_rays);
    const KVec3 a = k_vertex_light_sum(&now), b = k_vertex_light_sum(&later);
    ASSERT_EQ(std::memcmp(&a, &b, sizeof a), 0) << "trial " << trial;
  }
  EXPECT_GT(visible_some, 100);
  EXPECT_GT(blocked_some, 100);
}

TEST(KernelShadowQueue, AVertexGetsASlotForEveryRayItCanEmitOrNone) {
  KFrameParams p{};
  p.light_sampling = K_LIGHTS_TREE;
  p.light_samples = 1;
  p.emissive_samples = 1;
  EXPECT_EQ(k_shadow_queue_slots(&p, 300, 12), 2u);
  EXPECT_EQ(k_shadow_queue_slots(&p, 300, 0), 1u) << "no emitters, no emissive ray";
  p.emissive_samples = 0;
  EXPECT_EQ(k_shadow_queue_slots(&p, 300, 12), 1u);
  p.emissive_samples = 1;
  p.light_samples = 7;
  EXPECT_EQ(k_shadow_queue_slots(&p, 300, 12), 8u);
  p.light_samples = 8;
  EXPECT_EQ(k_shadow_queue_slots(&p, 300, 12), 0u) << "past K_SHADOW_QUEUE_MAX: walked as they come";
  p.light_sampling = K_LIGHTS_GATHER;
  p.light_samples = 4;
  EXPECT_EQ(k_shadow_queue_slots(&p, 300, 12), 5u);
  p.light_sampling = K_LIGHTS_EVERY;
  EXPECT_EQ(k_shadow_queue_slots(&p, 7, 12), 8u) << "every: a ray per light of the map";
  EXPECT_EQ(k_shadow_queue_slots(&p, 8, 12), 0u);
  p.light_sampling = K_LIGHTS_TREE;
  p.light_samples = 0;  // every light, whatever the sampling says
  EXPECT_EQ(k_shadow_queue_slots(&p, 5, 0), 5u);
  EXPECT_EQ(k_shadow_queue_slots(&p, 9, 0), 0u);
}
