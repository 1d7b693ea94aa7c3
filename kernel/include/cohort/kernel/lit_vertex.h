/* An opaque vertex between its two halves of shading (integrator.h's k_path_hit_lit, then k_path_vertex_end):
 * lit by the Doom 3 lights, its emissive sample and bounce still to come. Two halves so that a tracer may pick
 * the emissive triangles of many vertices together in between (emissive_tree.h's KEmissivePick: the Embree
 * tracer's wavefront); the others shade a vertex to its end in one call (k_path_hit_queued, path_segment.h's
 * k_path_segment), which never stores one of these. */
#ifndef COHORT_KERNEL_LIT_VERTEX_H
#define COHORT_KERNEL_LIT_VERTEX_H
#include "material.h"
#include "rng.h"

typedef struct KLitVertex {
  KSurface sf;          /* as the light samples saw it (regularised after a bounce) */
  KVec3 wo;             /* toward where the ray came from */
  KVec3 contribution;   /* its emission and environment: the vertex light's base */
  KRng rng;             /* the path's stream after the light samples */
  float path_weight;
  int emissive_nee;     /* it takes an emissive sample */
} KLitVertex;

/* k_path_hit_lit's and k_path_segment_lit's answer at such a vertex (beside 0: the path ended, 1: it goes on). */
#define K_PATH_VERTEX_LIT 2

#endif
