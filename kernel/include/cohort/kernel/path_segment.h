/* A path from its current ray up to its next bounce: what every tracer's loop over k_path_hit_lit and
 * k_path_vertex_end does, written once. The megakernels and the host tracers run a whole path as segments
 * one after the other (integrator.h's k_trace_path); the wavefront tracers (tracers/cuda, tracers/opencl)
 * run one segment per shading kernel, the path waiting in memory (path_state.h) while its next ray is walked
 * by a kernel of its own. integrator.h includes this header once k_path_hit_queued is defined: include
 * integrator.h. */
#ifndef COHORT_KERNEL_PATH_SEGMENT_H
#define COHORT_KERNEL_PATH_SEGMENT_H

/* Runs the path from its current ray (s->org, s->dir) up to its next opaque vertex's Doom 3 lights: 0 when it
 * ends before, K_PATH_VERTEX_LIT at the vertex (k_path_vertex_end ends its shading, from *lit). traced: the
 * current ray's hit, walked already by a wavefront's walk kernel (instance K_NONE: a miss; null: walked here).
 * Transparent layers are walked here. shadows (empty on entry): where the opaque vertex's shadow rays go; with
 * some left in its slots (shadows->count > 0) the vertex's light waits in *vertex (k_path_hit_lit). */
KFN int k_path_segment_lit(KTraceCtx* ctx, const KFrameParams* params, KPathState* s, const KHit* traced,
                           KGLOBAL KPathFirstHit* first_hit, KShadowQueue* shadows, KVertexLight* vertex,
                           KLitVertex* lit) {
  for (;;) {
    KHit hit;
    int met;
    if (traced) {
      hit = *traced;
      met = hit.instance != K_NONE;
      traced = 0;
    } else {
      hit.cost = 0u;
      met = k_trace_closest(ctx, s->org, s->dir, K_INF, K_RAY_PRIMARY, &hit);
    }
    if (!met) {
      k_path_miss(K_CTX_SCENE(ctx), params, s, &hit);
      return 0;
    }
    int shaded = k_path_hit_lit(ctx, params, s, hit, first_hit, shadows, vertex, lit);
    if (shaded != 1) return shaded;
  }
}

/* Runs the path from its current ray (s->org, s->dir) until it ends (0) or has bounced (1: its next ray in
 * *s): k_path_segment_lit's walk with each hit shaded to its end (k_path_hit_queued), what every tracer but
 * the Embree wavefront runs. Arguments as k_path_segment_lit's. A loop of its own, not k_path_segment_lit
 * with a null KLitVertex: the GPU kernels compile as before the split only so (ptxas sm_90: the one loop
 * moved their spills by a few bytes; the two halves called after it, by 40-60 %). */
KFN int k_path_segment(KTraceCtx* ctx, const KFrameParams* params, KPathState* s, const KHit* traced,
                       KGLOBAL KPathFirstHit* first_hit, KShadowQueue* shadows, KVertexLight* vertex) {
  kuint bounce = s->bounce;
  for (;;) {
    KHit hit;
    int met;
    if (traced) {
      hit = *traced;
      met = hit.instance != K_NONE;
      traced = 0;
    } else {
      hit.cost = 0u;
      met = k_trace_closest(ctx, s->org, s->dir, K_INF, K_RAY_PRIMARY, &hit);
    }
    if (!met) {
      k_path_miss(K_CTX_SCENE(ctx), params, s, &hit);
      return 0;
    }
    if (!k_path_hit_queued(ctx, params, s, hit, first_hit, shadows, vertex)) return 0;
    if (s->bounce != bounce) return 1;
  }
}

#endif
