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
/* K_LIGHTS_IN_RANGE_BOUNDED: the lights in range weighed one by one before the rest is sampled, and the
 * candidates drawn from that rest (k_light_tree_pick's weigh_first): at most their sum weighed a pick. */
#define K_IN_RANGE_WEIGH_FIRST 8u
#define K_IN_RANGE_CANDIDATES 8u
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

/* A guess, from the leaf's node alone (already read by the walk), of how much its light gives the point
 * p with normal `normal`: its power times the windowed falloff of a point light filling the leaf's box,
 * (1 - d^2)^2 with d the box-normalised distance from the box's centre, times the cosine toward that
 * centre, each with a floor (K_IN_RANGE_GUESS_FLOOR) so that no light whose box holds p is left out: a
 * light's own falloff image, projection or centre may differ from the guess. What
 * K_LIGHTS_IN_RANGE_BOUNDED draws its candidates by; their weights are still their contributions. */
#define K_IN_RANGE_GUESS_FLOOR 0.02f
KFN float k_light_leaf_guess(KGLOBAL const KLightNode* n, KVec3 p, KVec3 normal) {
  KVec3 lo = v3(n->bmin[0], n->bmin[1], n->bmin[2]), hi = v3(n->bmax[0], n->bmax[1], n->bmax[2]);
  KVec3 centre = v3_scale(v3_add(lo, hi), 0.5f), half = v3_scale(v3_sub(hi, lo), 0.5f);
  KVec3 d = v3_sub(p, centre);
  float dx = half.x > 0.0f ? d.x / half.x : 0.0f, dy = half.y > 0.0f ? d.y / half.y : 0.0f,
        dz = half.z > 0.0f ? d.z / half.z : 0.0f;
  float falloff = k_window_falloff(dx * dx + dy * dy + dz * dz);
  float dist = v3_length(d);
  float cosine = dist > 0.0f ? k_fmax(-v3_dot(normal, d) / dist, 0.0f) : 1.0f;
  return n->power * (falloff + K_IN_RANGE_GUESS_FLOOR) * (cosine + K_IN_RANGE_GUESS_FLOOR);
}

/* One light for the surface point, or K_NONE when none can reach it. On a pick, *contribution is its
 * unshadowed contribution toward wo and *pdf the probability that it was picked. u_descend and u_pick
 * are independent uniform numbers. descend_above: the descent goes on while a node holds more lights than
 * this (K_LIGHT_TREE_GATHER: the tree; K_NONE: no descent, the reservoir over every light whose box holds
 * the point, K_LIGHTS_IN_RANGE). weigh_first: how many of the lights in range the reservoir weighs in walk
 * order (K_NONE: all); with more in range, K_IN_RANGE_CANDIDATES of the rest are drawn in a second walk
 * (systematic, with u_descend) and weighed over their probability of being drawn
 * (K_LIGHTS_IN_RANGE_BOUNDED, descend_above = K_NONE): the count of lights weighed stays at most
 * weigh_first + K_IN_RANGE_CANDIDATES, however many reach the point, and with at most weigh_first of them
 * the pick is K_LIGHTS_IN_RANGE's, float for float. The candidates are drawn by a guess from the leaves'
 * nodes (k_light_leaf_guess), which the walks read anyway.
 *
 * Why the second: the descent weighs a child by its lights' power wherever its box holds the point, and a
 * child's box (the union of its lights') holds many points that none of its lights reach. On the large
 * generated map (295 lights, 3.8 in range of a point) half the tree's picks at the camera rays' hits ended
 * without a shadow ray (0.26 a path against 0.53 for the pick in range: no light found, or one too faint for
 * the shadow roulette), and its RMSE was 3.3x the pick in range's (docs/integrator.md, "One light among those
 * in range"). */
KFN kuint k_light_tree_pick(const KSceneView* scene, const KSurface* sf, KVec3 wo, float spec_boost, kuint descend_above,
                            kuint weigh_first, float u_descend, float u_pick, KVec3* contribution, float* pdf) {
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
  kuint in_range = 0u;   /* lights whose box holds p, in walk order (the first weigh_first are weighed) */
  float rest_guess = 0.0f;   /* the sum of the others' k_light_leaf_guess */
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
    if (++in_range > weigh_first) {
      rest_guess += k_light_leaf_guess(n, p, sf->normal);
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
  if (in_range > weigh_first && rest_guess > 0.0f) {
    /* More lights in range than weigh_first (K_LIGHTS_IN_RANGE_BOUNDED in a dense room): a second walk
     * draws candidates from the rest, each light i with probability q_i = min(1, K_IN_RANGE_CANDIDATES x
     * g_i / G) (g_i its k_light_leaf_guess, G their sum over the rest), systematically (one uniform,
     * u_descend, for the whole walk: at most K_IN_RANGE_CANDIDATES candidates, each light still taken with
     * probability exactly q_i), and each candidate joins the reservoir with weight w_i / q_i. The light
     * kept, y, has probability (w_y / q_y) / total among the candidates, so contribution_y x total / w_y,
     * i.e. contribution / pdf with pdf = w_y / total, has mean sum over the candidates of contribution_i /
     * q_i, whose mean over the draw is the sum of every light's contribution: unbiased (resampled
     * importance sampling). The descent's random number is free here: this walk starts at the root
     * (descend_above = K_NONE). */
    float scale = (float)K_IN_RANGE_CANDIDATES / rest_guess;
    float position = u_descend;
    kuint seen = 0u, taken = 0u;
    depth = 0u;
    stack[depth++] = node;
    while (depth > 0u && taken < K_IN_RANGE_CANDIDATES) {
      KGLOBAL const KLightNode* n = &scene->light_nodes[stack[--depth]];
      if (!k_light_node_holds(n, p)) continue;
      if (n->count == 0u) {
        if (depth + 2u <= (kuint)K_LIGHT_TREE_STACK) {
          stack[depth++] = n->left_first + 1u;
          stack[depth++] = n->left_first;
        }
        continue;
      }
      if (++seen <= weigh_first) continue;
      float q = k_fmin(k_light_leaf_guess(n, p, sf->normal) * scale, 1.0f);
      float before = position;
      position = before + q;
      if (!(k_floor(position) > k_floor(before))) continue;
      ++taken;
      KVec3 c = k_light_unshadowed(scene, &scene->lights[n->left_first], sf, wo, spec_boost);
      float w = v3_luminance(c);
      if (!(w > 0.0f)) continue;
      float r = w / q;
      total += r;
      if (u_pick * total < r) {
        chosen = n->left_first;
        chosen_weight = w;
        chosen_contribution = c;
        u_pick = u_pick * total / r;
      } else {
        u_pick = (u_pick * total - r) / (total - r);
      }
      u_pick = k_fmin(u_pick, 0.99999994f);
    }
  }
  if (chosen == K_NONE) return K_NONE;
  *contribution = chosen_contribution;
  *pdf = prob * chosen_weight / total;
  return chosen;
}

#endif
