/* Gathering, through the light tree (layout.h, KLightNode), every Doom 3 light whose box holds a point,
 * for the `gather` light sampling (KFrameParams.light_sampling == K_LIGHTS_GATHER, integrator.h's
 * k_direct_lighting_gather). The walk visits only the nodes whose box holds the point: about the tree's
 * depth times the lights found, whatever the map's light count (the large generated map: 295 lights,
 * 3.77 a point).
 *
 * With at most N of them (N = light_samples) each gets its own shadow ray, in light index order, with
 * the same random numbers as K_LIGHTS_EVERY: the same image. With more, each light i is traced with
 * probability q_i = min(1, N w_i / W) (w_i the largest channel of its unshadowed contribution, W
 * their sum) and weighted 1 / q_i: lights bright at the point always get their ray,
 * faint ones share the rest. The choice is systematic (one uniform u for the whole list: light i is taken
 * when [u + q_1 + ... + q_(i-1), u + q_1 + ... + q_i) holds an integer), so the count of rays is
 * floor or ceil of sum q_i <= N and never more, and each light is still taken with probability exactly
 * q_i > 0: unbiased wherever `every` is. */
#ifndef COHORT_KERNEL_LIGHT_GATHER_H
#define COHORT_KERNEL_LIGHT_GATHER_H
#include "light_tree.h"
#include "rng.h"

/* Most lights a hit traces one by one in gather mode (light_samples above this count as this). */
#define K_LIGHT_GATHER_MAX 16u

/* A walk over the lights whose box holds one point, in the tree's leaf order. */
typedef struct KLightWalk {
  kuint stack[K_LIGHT_TREE_STACK];
  kuint depth;
} KLightWalk;

KFN void k_light_walk_begin(const KSceneView* scene, KLightWalk* walk) {
  walk->depth = 0u;
  if (k_light_tree_nodes(scene) > 0u) walk->stack[walk->depth++] = 0u;
}

/* The next light whose box holds p, K_NONE when the walk is done. The core builds the tree by median
 * splits, so the stack holds at most its depth plus one node (K_LIGHT_TREE_STACK: 2^15 lights). */
KFN kuint k_light_walk_next(const KSceneView* scene, KVec3 p, KLightWalk* walk) {
  while (walk->depth > 0u) {
    KGLOBAL const KLightNode* n = &scene->light_nodes[walk->stack[--walk->depth]];
    if (!k_light_node_holds(n, p)) continue;
    if (n->count > 0u) return n->left_first;
    if (walk->depth + 2u <= (kuint)K_LIGHT_TREE_STACK) {
      walk->stack[walk->depth++] = n->left_first + 1u;
      walk->stack[walk->depth++] = n->left_first;
    }
  }
  return K_NONE;
}

/* Inserts light into the ascending list[0..count) (count < K_LIGHT_GATHER_MAX). */
KFN void k_light_list_insert(kuint* list, kuint count, kuint light) {
  kuint i = count;
  while (i > 0u && list[i - 1u] > light) {
    list[i] = list[i - 1u];
    --i;
  }
  list[i] = light;
}

/* Systematic selection: the light whose probability q follows `*position` (u plus the q's before it)
 * is taken when the step crosses an integer. Probability exactly q for u uniform in [0, 1). */
KFN int k_systematic_take(float* position, float q) {
  float before = *position;
  *position = before + q;
  return k_floor(*position) > k_floor(before);
}

/* The light samples gather mode traces at one point: light[k] with `value[k]`, its unshadowed
 * contribution over its probability of being traced; rng: the stream after the choice. */
typedef struct KLightGather {
  KRng rng;
  kuint count;
  kuint light[K_LIGHT_GATHER_MAX];
  KVec3 value[K_LIGHT_GATHER_MAX];
} KLightGather;

/* Which lights to trace at sf for at most `budget` shadow rays (see the top of this file). Two walks over
 * the tree: the first counts the lights that reach the point, keeps the first `budget` of them in index
 * order and sums their weights; the second, only with more than `budget`, chooses. With at most `budget`
 * lights no random number is drawn, so `every`'s stream follows unchanged. Arguments by value and
 * outlined: CUDA's megakernel keeps its scene, surface and random state in registers on the other paths. */
KFN_OUTLINED KLightGather k_light_gather(KSceneView scene, KSurface sf, KVec3 wo, float spec_boost, kuint budget,
                                         KRng rng) {
  KLightGather out;
  out.rng = rng;
  out.count = 0u;
  if (budget > K_LIGHT_GATHER_MAX) budget = K_LIGHT_GATHER_MAX;
  kuint found = 0u;
  float total = 0.0f;
  KLightWalk walk;
  k_light_walk_begin(&scene, &walk);
  for (kuint i = k_light_walk_next(&scene, sf.position, &walk); i != K_NONE;
       i = k_light_walk_next(&scene, sf.position, &walk)) {
    float w = v3_max_component(k_light_unshadowed(&scene, &scene.lights[i], &sf, wo, spec_boost));
    if (!(w > 0.0f)) continue;
    if (found < budget) k_light_list_insert(out.light, found, i);
    ++found;
    total += w;
  }
  if (found <= budget) {
    for (kuint k = 0u; k < found; ++k)
      out.value[k] = k_light_unshadowed(&scene, &scene.lights[out.light[k]], &sf, wo, spec_boost);
    out.count = found;
    return out;
  }
  float position = k_rng_next(&out.rng);
  float scale = (float)budget / total;
  k_light_walk_begin(&scene, &walk);
  for (kuint i = k_light_walk_next(&scene, sf.position, &walk); i != K_NONE && out.count < budget;
       i = k_light_walk_next(&scene, sf.position, &walk)) {
    KVec3 c = k_light_unshadowed(&scene, &scene.lights[i], &sf, wo, spec_boost);
    float w = v3_max_component(c);
    if (!(w > 0.0f)) continue;
    float q = k_fmin(w * scale, 1.0f);
    if (!k_systematic_take(&position, q)) continue;
    out.light[out.count] = i;
    out.value[out.count] = v3_scale(c, 1.0f / q);
    ++out.count;
  }
  return out;
}

#endif
