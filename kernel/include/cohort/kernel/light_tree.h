/* Picking one Doom 3 light for next-event estimation through the light tree (layout.h, KLightNode), at a
 * cost bounded by the tree's depth plus K_LIGHT_TREE_GATHER lights, whatever the map's light count.
 *
 * 1. Descent: from the root, while the node holds more than K_LIGHT_TREE_GATHER lights, step into one
 *    child with probability proportional to its importance, power x [p inside its box] (a light is zero
 *    outside its box, so a subtree whose box misses p cannot contribute).
 * 2. Gather: in the subtree reached, every light whose box holds p is weighed by its unshadowed
 *    contribution w_i (luminance), and one is kept by a single-slot reservoir: probability w_i / W.
 *
 * pdf(light i) = prod over descent steps of importance(child taken) / (importance(left) + importance(right))
 *                x w_i / W.
 * Every light that contributes at p has all its ancestors' boxes holding p and nonzero power, so it
 * has a nonzero pdf: the estimator contribution / pdf is unbiased. In a map with at most
 * K_LIGHT_TREE_GATHER lights the descent is empty and the pick is the exact product-of-contributions
 * pick of K_LIGHTS_ALL over only the lights that reach p. */
#ifndef COHORT_KERNEL_LIGHT_TREE_H
#define COHORT_KERNEL_LIGHT_TREE_H
#include "lights.h"

#define K_LIGHT_TREE_GATHER 16u
/* The core builds the tree by median splits, so a subtree of n lights is ceil(log2 n) deep and the
 * gather stack never holds more than that plus one node. */
#define K_LIGHT_TREE_STACK 16

KFN int k_light_node_holds(KGLOBAL const KLightNode* n, KVec3 p) {
  return p.x >= n->bmin[0] && p.x <= n->bmax[0] && p.y >= n->bmin[1] && p.y <= n->bmax[1] && p.z >= n->bmin[2] &&
         p.z <= n->bmax[2];
}

KFN float k_light_node_importance(KGLOBAL const KLightNode* n, KVec3 p) {
  return k_light_node_holds(n, p) ? n->power : 0.0f;
}

/* One light for the surface point, or K_NONE when none can reach it. On a pick, *contribution is its
 * unshadowed contribution toward wo and *pdf the probability that it was picked. u_descend and u_pick
 * are independent uniform numbers. descend_above: the descent goes on while a node holds more lights than
 * this (K_LIGHT_TREE_GATHER: the tree; K_NONE: no descent, the reservoir over every light whose box holds
 * the point, K_LIGHTS_IN_RANGE).
 *
 * Why the second: the descent weighs a child by its lights' power wherever its box holds the point, and a
 * child's box (the union of its lights') holds many points that none of its lights reach. On the large
 * generated map (295 lights, 3.8 in range of a point) half the tree's picks at the camera rays' hits ended
 * without a shadow ray (0.26 a path against 0.53 for the pick in range: no light found, or one too faint for
 * the shadow roulette), and its RMSE was 3.3x the pick in range's (docs/integrator.md, "One light among those
 * in range"). */
KFN kuint k_light_tree_pick(const KSceneView* scene, const KSurface* sf, KVec3 wo, float spec_boost, kuint descend_above,
                            float u_descend, float u_pick, KVec3* contribution, float* pdf) {
  KVec3 p = sf->position;
  if (k_light_tree_nodes(scene) == 0u || !k_light_node_holds(&scene->light_nodes[0], p)) return K_NONE;
  kuint node = 0u;
  float prob = 1.0f;
  while (scene->light_nodes[node].count == 0u && scene->light_nodes[node].light_count > descend_above) {
    kuint left = scene->light_nodes[node].left_first;
    float wl = k_light_node_importance(&scene->light_nodes[left], p);
    float wr = k_light_node_importance(&scene->light_nodes[left + 1u], p);
    float total = wl + wr;
    if (!(total > 0.0f)) return K_NONE;
    float pl = wl / total;
    if (u_descend < pl) {
      node = left;
      prob *= pl;
      u_descend = u_descend / pl;
    } else {
      node = left + 1u;
      prob *= 1.0f - pl;
      u_descend = (u_descend - pl) / (1.0f - pl);
    }
    u_descend = k_fmin(u_descend, 0.99999994f);
  }

  kuint stack[K_LIGHT_TREE_STACK];
  kuint depth = 0u;
  stack[depth++] = node;
  float total = 0.0f, chosen_weight = 0.0f;
  kuint chosen = K_NONE;
  KVec3 chosen_contribution = v3s(0.0f);
  while (depth > 0u) {
    KGLOBAL const KLightNode* n = &scene->light_nodes[stack[--depth]];
    if (!k_light_node_holds(n, p)) continue;
    if (n->count == 0u) {
      if (depth + 2u <= (kuint)K_LIGHT_TREE_STACK) {
        stack[depth++] = n->left_first + 1u;
        stack[depth++] = n->left_first;
      }
      continue;
    }
    KVec3 c = k_light_unshadowed(scene, &scene->lights[n->left_first], sf, wo, spec_boost);
    float w = v3_luminance(c);
    if (!(w > 0.0f)) continue;
    total += w;
    /* Single-slot reservoir: keep this light with probability w / total. */
    if (u_pick * total < w) {
      chosen = n->left_first;
      chosen_weight = w;
      chosen_contribution = c;
      u_pick = u_pick * total / w;
    } else {
      u_pick = (u_pick * total - w) / (total - w);
    }
    u_pick = k_fmin(u_pick, 0.99999994f);
  }
  if (chosen == K_NONE) return K_NONE;
  *contribution = chosen_contribution;
  *pdf = prob * chosen_weight / total;
  return chosen;
}

#endif
