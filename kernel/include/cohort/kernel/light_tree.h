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

/* Whether the node's box holds p. A tracer may give its own test with the same answer by defining
 * K_LIGHT_NODE_HOLDS(n, p) before including the kernel headers (Embree: SSE, embree_light_box.h). */
KFN int k_light_node_holds(KGLOBAL const KLightNode* n, KVec3 p) {
#ifdef K_LIGHT_NODE_HOLDS
  return K_LIGHT_NODE_HOLDS(n, p);
#else
  return p.x >= n->bmin[0] && p.x <= n->bmax[0] && p.y >= n->bmin[1] && p.y <= n->bmax[1] && p.z >= n->bmin[2] &&
         p.z <= n->bmax[2];
#endif
}

KFN float k_light_node_importance(KGLOBAL const KLightNode* n, KVec3 p) {
  return k_light_node_holds(n, p) ? n->power : 0.0f;
}

/* The integral over t in [a, b] (clamped to [-1, 1]) of the window (1 - t^2)^2: its antiderivative
 * t - 2t^3/3 + t^5/5 at both ends. */
KFN float k_window_integral(float a, float b) {
  a = k_fmin(k_fmax(a, -1.0f), 1.0f);
  b = k_fmin(k_fmax(b, -1.0f), 1.0f);
  float a2 = a * a, b2 = b * b;
  return b * (1.0f + b2 * (-2.0f / 3.0f + b2 * 0.2f)) - a * (1.0f + a2 * (-2.0f / 3.0f + a2 * 0.2f));
}

/* A guess, from a node alone, of how much its lights give the point p with normal `normal`: the importance
 * of K_LIGHTS_DENSE's descent (from the reverted in-range-bounded, docs/integrator.md). Model: the node's
 * lights are point lights of half-extent reach (layout.h: the largest below) with their centres spread evenly
 * over the node's box shrunk by reach, each lighting p by its box's window (1 - d^2)^2, taken per axis. Their
 * mean is a product over the axes of the window's mean over the centres' interval (its integral over the
 * interval's length, or its value at the one centre where that length is zero: a leaf, lights in one plane),
 * times the power and the cosine toward the centres' box (1 where p's tangent plane cuts it). The tree's own
 * importance, power wherever the box holds p, weighs a subtree of lights all beyond reach of p like one
 * around it. Floors (K_LIGHT_GUESS_FLOOR, K_LIGHT_GUESS_MEAN_FLOOR) keep every node whose box holds p above
 * zero: a light's own falloff image, projection, shape or centre may differ from the model, and an unbiased
 * pick needs every light that reaches p to be reachable. The constants were chosen on the bench rooms and
 * the test floors by the branch that introduced the guess (lightbound). */
#define K_LIGHT_GUESS_FLOOR 0.02f
#define K_LIGHT_GUESS_MEAN_FLOOR 1e-4f
KFN float k_light_node_guess(KGLOBAL const KLightNode* n, KVec3 p, KVec3 normal) {
  if (!k_light_node_holds(n, p)) return 0.0f;
  float r = n->reach;
  if (!(r > 0.0f)) return n->power;   /* no size known: the tree's importance */
  float mean = 1.0f, facing = 0.0f, centre_dist2 = 0.0f;
  float pv[3] = {p.x, p.y, p.z}, nv[3] = {normal.x, normal.y, normal.z};
  for (int k = 0; k < 3; ++k) {
    float lo = n->bmin[k] + r, hi = n->bmax[k] - r;
    if (lo > hi) lo = hi = 0.5f * (n->bmin[k] + n->bmax[k]);
    float len = hi - lo, mid = 0.5f * (lo + hi);
    if (len > 1e-3f * r) {
      mean *= r * k_window_integral((lo - pv[k]) / r, (hi - pv[k]) / r) / len;
    } else {
      float t = (mid - pv[k]) / r;
      mean *= k_window_falloff(t * t);
    }
    /* How far the centres' box reaches along the normal from p, and p's distance to its middle. */
    facing += nv[k] * (mid - pv[k]) + k_fabs(nv[k]) * 0.5f * len;
    centre_dist2 += (mid - pv[k]) * (mid - pv[k]);
  }
  float cosine = centre_dist2 > 0.0f ? k_fmin(k_fmax(facing / k_sqrt(centre_dist2), 0.0f), 1.0f) : 1.0f;
  return n->power * (k_fmax(mean, 0.0f) + K_LIGHT_GUESS_MEAN_FLOOR) * (cosine + K_LIGHT_GUESS_FLOOR);
}

/* One light for the surface point, or K_NONE when none can reach it. On a pick, *contribution is its
 * unshadowed contribution toward wo and *pdf the probability that it was picked. u_descend and u_pick
 * are independent uniform numbers. descend_above: the descent goes on while a node holds more lights than
 * this (K_LIGHT_TREE_GATHER: the tree; K_NONE: no descent, the reservoir over every light whose box holds
 * the point, K_LIGHTS_IN_RANGE; K_LIGHT_DENSE_LEAF with by_guess, K_LIGHTS_DENSE). by_guess: each step
 * weighs a child by k_light_node_guess instead of its power wherever its box holds the point (a constant
 * at every call, so that each caller's inlined copy keeps one importance only).
 *
 * Why the second: the descent weighs a child by its lights' power wherever its box holds the point, and a
 * child's box (the union of its lights') holds many points that none of its lights reach. On the large
 * generated map (295 lights, 3.8 in range of a point) half the tree's picks at the camera rays' hits ended
 * without a shadow ray (0.26 a path against 0.53 for the pick in range: no light found, or one too faint for
 * the shadow roulette), and its RMSE was 3.3x the pick in range's (docs/integrator.md, "One light among those
 * in range"). */
KFN kuint k_light_tree_pick(const KSceneView* scene, const KSurface* sf, KVec3 wo, float spec_boost, kuint descend_above,
                            int by_guess, float u_descend, float u_pick, KVec3* contribution, float* pdf) {
  KVec3 p = sf->position;
  if (k_light_tree_nodes(scene) == 0u || !k_light_node_holds(&scene->light_nodes[0], p)) return K_NONE;
  kuint node = 0u;
  float prob = 1.0f;
  while (scene->light_nodes[node].count == 0u && scene->light_nodes[node].light_count > descend_above) {
    kuint left = scene->light_nodes[node].left_first;
    float wl = by_guess ? k_light_node_guess(&scene->light_nodes[left], p, sf->normal)
                        : k_light_node_importance(&scene->light_nodes[left], p);
    float wr = by_guess ? k_light_node_guess(&scene->light_nodes[left + 1u], p, sf->normal)
                        : k_light_node_importance(&scene->light_nodes[left + 1u], p);
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

/* K_LIGHTS_DENSE, for rooms where many lights reach a point: the descent by k_light_node_guess to a node of
 * at most K_LIGHT_DENSE_LEAF lights, then the reservoir over the lights below it whose box holds p. At most
 * K_LIGHT_DENSE_LEAF lights weighed and two guesses a level however many lights reach p, where in-range
 * weighs every one (about 88 in bench_scaling's 1,024-light room). pdf = the steps' probabilities x
 * w / (sum of w in the node); the guess is above zero wherever a node's box holds p, so every light that
 * reaches p keeps a nonzero pdf: unbiased. Where the map has at most K_LIGHT_DENSE_LEAF lights it is
 * in-range's pick, float for float. */
#define K_LIGHT_DENSE_LEAF 8u
KFN kuint k_light_dense_pick(const KSceneView* scene, const KSurface* sf, KVec3 wo, float spec_boost, float u_descend,
                             float u_pick, KVec3* contribution, float* pdf) {
  return k_light_tree_pick(scene, sf, wo, spec_boost, K_LIGHT_DENSE_LEAF, 1, u_descend, u_pick, contribution, pdf);
}

#endif
