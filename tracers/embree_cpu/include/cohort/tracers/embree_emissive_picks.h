// The emissive tree's pick (kernel/emissive_tree.h's k_emissive_tree_pick) for many vertices at once, eight
// to an instruction stream, for the Embree tracer's wavefront: every vertex a stage lit waits for its pick
// (integrator.h's KLitVertex), so the descents of eight run side by side. One vertex's descent is a chain of
// dependent node loads and divisions with a coin toss at every level (u < pl, mispredicted half the time);
// eight side by side overlap their latencies, and the toss becomes a select. Per lane, the same operations in
// the same order as k_emissive_tree_pick, so the same triangle and the same probability (both the wavefront
// and the path-by-path tiles pick through here, so their images stay equal where the compiler contracts
// multiply-adds; EmbreeEmissivePicks.* compares with the portable pick in a build that does not).
#pragma once

#include <stdint.h>

#include "cohort/kernel/emissive_tree.h"

#if defined(__AVX2__)
#include <immintrin.h>
#endif

// The baseline build passes eight-float vectors between its inlined helpers (two SSE registers each); no
// function of another build sees them. (Not popped: GCC reports this at the end of the includer's file.)
#pragma GCC diagnostic ignored "-Wpsabi"

namespace cohort::tracers::embree_emissive {

typedef float F8 __attribute__((vector_size(32)));
typedef int32_t I8 __attribute__((vector_size(32)));

// KLightNode as floats: where each field starts.
constexpr int32_t kStride = 12, kBmin = 0, kLeftFirst = 3, kBmax = 4, kCount = 7, kPower = 8;
static_assert(sizeof(KLightNode) == kStride * sizeof(float), "KLightNode layout");

// base[index] in each lane whose mask is set; 0 elsewhere.
static inline F8 gather(const float* base, I8 index, I8 mask) {
#if defined(__AVX2__)
  return (F8)_mm256_mask_i32gather_ps(_mm256_setzero_ps(), base, (__m256i)index, (__m256)mask, 4);
#else
  F8 r = {};
  for (int k = 0; k < 8; ++k) r[k] = mask[k] ? base[index[k]] : 0.0f;
  return r;
#endif
}

static inline I8 gather_int(const float* base, I8 index, I8 mask) {
#if defined(__AVX2__)
  return (I8)_mm256_mask_i32gather_epi32(_mm256_setzero_si256(), reinterpret_cast<const int*>(base),
                                          (__m256i)index, (__m256i)mask, 4);
#else
  I8 r = {};
  for (int k = 0; k < 8; ++k) r[k] = mask[k] ? reinterpret_cast<const int32_t*>(base)[index[k]] : 0;
  return r;
#endif
}

static inline bool any(I8 mask) {
#if defined(__AVX2__)
  return _mm256_movemask_ps((__m256)mask) != 0;
#else
  for (int k = 0; k < 8; ++k)
    if (mask[k]) return true;
  return false;
#endif
}

// k_fmax / k_fmin on the host (portable.h): a, unless b is larger (smaller) or NaN.
static inline F8 fmax8(F8 a, F8 b) { return ((a > b) | (b != b)) ? a : b; }
static inline F8 fmin8(F8 a, F8 b) { return ((a < b) | (b != b)) ? a : b; }

static inline F8 splat(float x) { return F8{} + x; }

// k_emissive_importance of boxes [lo, hi] of these powers for the points (px, py, pz).
static inline F8 importance(F8 lox, F8 loy, F8 loz, F8 hix, F8 hiy, F8 hiz, F8 power, F8 px, F8 py, F8 pz) {
  const F8 half = splat(0.5f);
  const F8 hx = (hix - lox) * half, hy = (hiy - loy) * half, hz = (hiz - loz) * half;
  const F8 dx = px - (lox + hx), dy = py - (loy + hy), dz = pz - (loz + hz);
  const F8 floor2 = fmax8(hx * hx + hy * hy + hz * hz, splat(1e-6f));
  return power / fmax8(dx * dx + dy * dy + dz * dz, floor2);
}

// The same for the nodes at float offsets `at` (lanes of mask).
static inline F8 importance_at(const float* nodes, I8 at, I8 mask, F8 px, F8 py, F8 pz) {
  return importance(gather(nodes, at + kBmin, mask), gather(nodes, at + (kBmin + 1), mask),
                    gather(nodes, at + (kBmin + 2), mask), gather(nodes, at + kBmax, mask),
                    gather(nodes, at + (kBmax + 1), mask), gather(nodes, at + (kBmax + 2), mask),
                    gather(nodes, at + kPower, mask), px, py, pz);
}

// One step of k_emissive_tree_pick's descent in the lanes of live (pl: the left child's probability; left:
// its index): the probability, the number and the node after it.
static inline void step_down(I8 live, F8 pl, I8 left, F8* prob, F8* u, I8* node) {
  const I8 right = ~(*u < pl);
  const F8 step = right ? splat(1.0f) - pl : pl;
  const F8 next_u = fmin8((right ? *u - pl : *u) / step, splat(0.99999994f));
  *prob = live ? *prob * step : *prob;
  *u = live ? next_u : *u;
  *node = live ? left - right : *node;  // right is -1 where the step goes right
}

// Trees of at most this many nodes (32 emitters: the test map has 10, the large map 14) are descended from a
// table of every node's step for every lane, made first: each node's data is loaded once for all eight lanes,
// and a step reads two values per lane instead of gathering two nodes' fields.
constexpr kuint kTableNodes = 64u;

// The descent from the table: per lane and node (root-relative), the left child's probability and the left
// child, -1 at a leaf, -2 where the children have no power (no pick).
static inline void descend_table(const KSceneView* scene, kuint root, I8 live, F8 px, F8 py, F8 pz, F8* u, F8* prob,
                                 I8* node, I8* none) {
  const kuint count = k_emissive_tree_nodes(scene);
  const KLightNode* nodes = scene->light_nodes + root;
  alignas(32) F8 weight[kTableNodes];
  alignas(32) F8 left_prob[kTableNodes];
  alignas(32) I8 next[kTableNodes];
  for (kuint i = 1u; i < count; ++i) {
    const KLightNode& n = nodes[i];
    weight[i] = importance(splat(n.bmin[0]), splat(n.bmin[1]), splat(n.bmin[2]), splat(n.bmax[0]), splat(n.bmax[1]),
                           splat(n.bmax[2]), splat(n.power), px, py, pz);
  }
  for (kuint i = 0u; i < count; ++i) {
    if (nodes[i].count != 0u) {
      next[i] = I8{} - 1;
      continue;
    }
    const int32_t left = static_cast<int32_t>(nodes[i].left_first - root);
    const F8 total = weight[left] + weight[left + 1];
    left_prob[i] = weight[left] / total;
    next[i] = (total > 0.0f) ? I8{} + left : I8{} - 2;
  }
  const I8 lane = {0, 1, 2, 3, 4, 5, 6, 7};
  *node = I8{};
  for (;;) {
    const I8 at = *node * 8 + lane;
    const I8 left = gather_int(reinterpret_cast<const float*>(next), at, live);
    *none |= live & (left == -2);
    live &= left >= 0;
    if (!any(live)) break;
    step_down(live, gather(reinterpret_cast<const float*>(left_prob), at, live), left, prob, u, node);
  }
  *node += static_cast<int32_t>(root);
}

// The descent gathering each lane's nodes from the tree, for larger trees.
static inline void descend_nodes(const KSceneView* scene, kuint root, I8 live, F8 px, F8 py, F8 pz, F8* u, F8* prob,
                                 I8* node, I8* none) {
  const float* nodes = reinterpret_cast<const float*>(scene->light_nodes);
  *node = I8{} + static_cast<int32_t>(root);
  for (;;) {
    const I8 at = *node * kStride;
    live &= gather_int(nodes, at + kCount, live) == 0;  // leaves are done
    if (!any(live)) break;
    const I8 left = gather_int(nodes, at + kLeftFirst, live), left_at = left * kStride;
    const F8 wl = importance_at(nodes, left_at, live, px, py, pz);
    const F8 wr = importance_at(nodes, left_at + kStride, live, px, py, pz);
    const F8 total = wl + wr;
    const I8 dead = live & ~(total > 0.0f);
    *none |= dead;
    live &= ~dead;
    step_down(live, wl / total, left, prob, u, node);
  }
}

// Up to eight picks: lanes [0, lanes) of points and us.
static inline void picks8(const KSceneView* scene, int lanes, const KVec3* points, const float* us,
                          KEmissivePick* out) {
  const kuint root = k_emissive_root(scene);
  if (root == K_NONE) {
    for (int k = 0; k < lanes; ++k) out[k] = KEmissivePick{K_NONE, 0.0f};
    return;
  }
  F8 px = {}, py = {}, pz = {}, u = {};
  I8 live = {};
  for (int k = 0; k < lanes; ++k) {
    px[k] = points[k].x;
    py[k] = points[k].y;
    pz[k] = points[k].z;
    u[k] = us[k];
    live[k] = -1;
  }
  F8 prob = splat(1.0f);
  I8 node, none = {};  // none: lanes whose descent met children without power
  if (k_emissive_tree_nodes(scene) <= kTableNodes)
    descend_table(scene, root, live, px, py, pz, &u, &prob, &node, &none);
  else
    descend_nodes(scene, root, live, px, py, pz, &u, &prob, &node, &none);
  for (int k = 0; k < lanes; ++k) {
    if (none[k]) {
      out[k] = KEmissivePick{K_NONE, 0.0f};
    } else {
      out[k].index = scene->light_nodes[node[k]].left_first;
      out[k].prob = prob[k];
    }
  }
}

// The emissive triangle k_emissive_tree_pick(scene, points[i], us[i], ...) returns, and its probability, for
// each of the n points.
static inline void picks(const KSceneView* scene, int n, const KVec3* points, const float* us, KEmissivePick* out) {
  for (int first = 0; first < n; first += 8)
    picks8(scene, n - first < 8 ? n - first : 8, points + first, us + first, out + first);
}

}  // namespace cohort::tracers::embree_emissive
