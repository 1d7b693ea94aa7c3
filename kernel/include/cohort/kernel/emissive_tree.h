/* Picking one emissive triangle for next-event estimation through the emissive tree (layout.h,
 * KLightNode: the last 2E - 1 nodes of the light node array), so that nearby emitters are chosen far
 * more often than those across the map, at a cost of the tree's depth.
 *
 * Descent: from the root, step into a child with probability proportional to its importance at p,
 *   power / max(|p - box centre|^2, |box half diagonal|^2)
 * (the inverse-square falloff of its power, bounded while p is near or inside the box), down to a leaf,
 * which holds one triangle. Every importance is positive for a node with power, so every emitter keeps
 * a nonzero probability wherever p is: the estimator stays unbiased, and k_emissive_tree_pdf gives the
 * same probability for any triangle by walking from its leaf up to the root (parent links). */
#ifndef COHORT_KERNEL_EMISSIVE_TREE_H
#define COHORT_KERNEL_EMISSIVE_TREE_H
#include "scene_view.h"
#include "vec.h"

/* An emissive triangle picked ahead of its vertex's sample: what k_emissive_tree_pick returns at the vertex
 * for the sample's first random number (index K_NONE: none), from a tracer that picks for many vertices at
 * once (the Embree tracer's wavefront, tracers/embree_cpu). */
typedef struct KEmissivePick {
  kuint index;
  float prob;
} KEmissivePick;

/* The emissive tree's root, or K_NONE when there are no emitters (or no tree for them). */
KFN kuint k_emissive_root(const KSceneView* scene) {
  return k_emissive_tree_nodes(scene) > 0u ? k_light_tree_nodes(scene) : K_NONE;
}

KFN float k_emissive_importance(KGLOBAL const KLightNode* n, KVec3 p) {
  KVec3 lo = v3(n->bmin[0], n->bmin[1], n->bmin[2]), hi = v3(n->bmax[0], n->bmax[1], n->bmax[2]);
  KVec3 half_extent = v3_scale(v3_sub(hi, lo), 0.5f);
  KVec3 d = v3_sub(p, v3_add(lo, half_extent));
  float floor2 = k_fmax(v3_dot(half_extent, half_extent), 1e-6f);
  return n->power / k_fmax(v3_dot(d, d), floor2);
}

/* The probability of stepping from interior node `parent` into `child`. */
KFN float k_emissive_step(const KSceneView* scene, kuint parent, kuint child, KVec3 p) {
  kuint left = scene->light_nodes[parent].left_first;
  float wl = k_emissive_importance(&scene->light_nodes[left], p);
  float wr = k_emissive_importance(&scene->light_nodes[left + 1u], p);
  float total = wl + wr;
  if (!(total > 0.0f)) return 0.0f;
  return (child == left ? wl : wr) / total;
}

/* One emissive triangle for the point p (an index into scene->emissive) and its probability *pick, or
 * K_NONE. u is a uniform number in [0, 1). */
KFN kuint k_emissive_tree_pick(const KSceneView* scene, KVec3 p, float u, float* pick) {
  kuint node = k_emissive_root(scene);
  if (node == K_NONE) return K_NONE;
  float prob = 1.0f;
  while (scene->light_nodes[node].count == 0u) {
    kuint left = scene->light_nodes[node].left_first;
    float wl = k_emissive_importance(&scene->light_nodes[left], p);
    float wr = k_emissive_importance(&scene->light_nodes[left + 1u], p);
    float total = wl + wr;
    if (!(total > 0.0f)) return K_NONE;
    float pl = wl / total;
    if (u < pl) {
      node = left;
      prob *= pl;
      u = u / pl;
    } else {
      node = left + 1u;
      prob *= 1.0f - pl;
      u = (u - pl) / (1.0f - pl);
    }
    u = k_fmin(u, 0.99999994f);
  }
  *pick = prob;
  return scene->light_nodes[node].left_first;
}

/* The index in scene->emissive of (instance, triangle), or K_NONE when it does not emit. */
KFN kuint k_emissive_find(const KSceneView* scene, kuint instance, kuint triangle) {
  kuint lo = 0u, hi = scene->emissive_count;
  while (lo < hi) {
    kuint mid = (lo + hi) / 2u;
    KGLOBAL const KEmissiveTriangle* e = &scene->emissive[mid];
    if (e->instance < instance || (e->instance == instance && e->triangle < triangle)) lo = mid + 1u; else hi = mid;
  }
  if (lo < scene->emissive_count && scene->emissive[lo].instance == instance && scene->emissive[lo].triangle == triangle)
    return lo;
  return K_NONE;
}

/* The probability that k_emissive_tree_pick at p returns emissive triangle `index`. */
KFN float k_emissive_tree_pdf(const KSceneView* scene, KVec3 p, kuint index) {
  if (index == K_NONE || k_emissive_root(scene) == K_NONE) return 0.0f;
  kuint node = scene->emissive[index].leaf;
  float prob = 1.0f;
  /* Median splits keep the tree under 64 levels for any count that fits a kuint; the bound only
   * guards against a corrupt parent chain. */
  for (int level = 0; level < 64 && scene->light_nodes[node].parent != K_NONE; ++level) {
    kuint parent = scene->light_nodes[node].parent;
    prob *= k_emissive_step(scene, parent, node, p);
    node = parent;
  }
  return prob;
}

#endif
