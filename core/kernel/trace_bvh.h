/* Ray tracing over the portable two-level BVH (layout.h) for tracers without a native ray tracing
 * API (OpenCL, CUDA): defines KTraceCtx, k_trace_closest and k_trace_occluded as integrator.h expects.
 * Candidate hits go through K_SURFACE_TRANSMITTANCE (default: k_hit_transmittance from material.h)
 * so alpha tests, pass-through surfaces and noShadows materials behave as under Embree's filters.
 * Include this, then integrator.h. */
#ifndef COHORT_KERNEL_TRACE_BVH_H
#define COHORT_KERNEL_TRACE_BVH_H
#include "material.h"

#ifndef K_SURFACE_TRANSMITTANCE
#define K_SURFACE_TRANSMITTANCE(scene, instance, triangle, u, v, shadow_ray) \
  k_hit_transmittance(scene, instance, triangle, u, v, shadow_ray)
#endif

#define K_BVH_STACK 64

typedef struct KTraceCtx {
  KSceneView scene;
  kuint tlas_node_count;
} KTraceCtx;

/* Two-sided Moller-Trumbore; (u, v) weight v1 and v2. */
KFN int k_ray_triangle(KVec3 o, KVec3 d, KVec3 p0, KVec3 p1, KVec3 p2, float tmax, float* t, float* u, float* v) {
  KVec3 e1 = v3_sub(p1, p0), e2 = v3_sub(p2, p0);
  KVec3 pv = v3_cross(d, e2);
  float det = v3_dot(e1, pv);
  if (k_fabs(det) < 1e-12f) return 0;
  float inv = 1.0f / det;
  KVec3 tv = v3_sub(o, p0);
  float uu = v3_dot(tv, pv) * inv;
  if (uu < 0.0f || uu > 1.0f) return 0;
  KVec3 qv = v3_cross(tv, e1);
  float vv = v3_dot(d, qv) * inv;
  if (vv < 0.0f || uu + vv > 1.0f) return 0;
  float tt = v3_dot(e2, qv) * inv;
  if (tt <= 0.0f || tt >= tmax) return 0;
  *t = tt;
  *u = uu;
  *v = vv;
  return 1;
}

/* Entry distance of the ray into a node's box, or a negative value when it misses within tmax. */
KFN float k_ray_box(KGLOBAL const KBvhNode* n, KVec3 o, KVec3 inv_d, float tmax) {
  float tx0 = (n->bmin[0] - o.x) * inv_d.x, tx1 = (n->bmax[0] - o.x) * inv_d.x;
  float ty0 = (n->bmin[1] - o.y) * inv_d.y, ty1 = (n->bmax[1] - o.y) * inv_d.y;
  float tz0 = (n->bmin[2] - o.z) * inv_d.z, tz1 = (n->bmax[2] - o.z) * inv_d.z;
  float tnear = k_fmax(k_fmax(k_fmin(tx0, tx1), k_fmin(ty0, ty1)), k_fmax(k_fmin(tz0, tz1), 0.0f));
  float tfar = k_fmin(k_fmin(k_fmax(tx0, tx1), k_fmax(ty0, ty1)), k_fmin(k_fmax(tz0, tz1), tmax));
  return tnear <= tfar ? tnear : -1.0f;
}

KFN KVec3 k_safe_inverse(KVec3 d) {
  return v3(1.0f / (k_fabs(d.x) > 1e-20f ? d.x : 1e-20f), 1.0f / (k_fabs(d.y) > 1e-20f ? d.y : 1e-20f),
            1.0f / (k_fabs(d.z) > 1e-20f ? d.z : 1e-20f));
}

/* Traverses one instance's BLAS with the ray in object space (t stays a world-space parameter because
 * the direction is transformed, not renormalised). any_hit: stop at the first accepted hit. */
KFN int k_trace_blas(const KSceneView* s, kuint instance, KVec3 o, KVec3 d, int any_hit, KHit* best, kuint* cost) {
  KBlas blas = s->blases[s->instances[instance].blas];
  if (blas.node_count == 0u) return 0;
  KGLOBAL const KBvhNode* nodes = s->blas_nodes + blas.node_offset;
  KVec3 inv_d = k_safe_inverse(d);
  kuint stack[K_BVH_STACK];
  int sp = 0;
  int found = 0;
  stack[sp++] = 0u;
  while (sp > 0) {
    KGLOBAL const KBvhNode* n = &nodes[stack[--sp]];
    *cost += 1u;
    if (k_ray_box(n, o, inv_d, best->t) < 0.0f) continue;
    if (n->count == 0u) {
      kuint l = n->left_first, r = n->left_first + 1u;
      float tl = k_ray_box(&nodes[l], o, inv_d, best->t), tr = k_ray_box(&nodes[r], o, inv_d, best->t);
      /* Push the farther child first so the nearer one is visited next. */
      if (tl >= 0.0f && tr >= 0.0f) {
        if (sp + 2 > K_BVH_STACK) continue;
        if (tl < tr) { stack[sp++] = r; stack[sp++] = l; }
        else { stack[sp++] = l; stack[sp++] = r; }
      } else if (tl >= 0.0f) {
        if (sp < K_BVH_STACK) stack[sp++] = l;
      } else if (tr >= 0.0f) {
        if (sp < K_BVH_STACK) stack[sp++] = r;
      }
      continue;
    }
    for (kuint i = 0u; i < n->count; ++i) {
      kuint tri_index = blas.tri_offset + n->left_first + i;
      KTriangle tri = s->triangles[tri_index];
      float t, u, v;
      if (!k_ray_triangle(o, d, v3_load_g(s->vertices[tri.v0].pos), v3_load_g(s->vertices[tri.v1].pos),
                          v3_load_g(s->vertices[tri.v2].pos), best->t, &t, &u, &v))
        continue;
      if (K_SURFACE_TRANSMITTANCE(s, instance, tri_index, u, v, any_hit) > 0.0f) continue;
      best->t = t;
      best->u = u;
      best->v = v;
      best->instance = instance;
      best->triangle = tri_index;
      found = 1;
      if (any_hit) return 1;
    }
  }
  return found;
}

KFN int k_trace_tlas(KTraceCtx* ctx, KVec3 org, KVec3 dir, float tmax, kuint ray_mask, int any_hit, KHit* hit) {
  const KSceneView* s = &ctx->scene;
  hit->t = tmax;
  hit->cost = 0u;
  if (ctx->tlas_node_count == 0u) return 0;
  KVec3 inv_d = k_safe_inverse(dir);
  kuint stack[K_BVH_STACK];
  int sp = 0;
  int found = 0;
  stack[sp++] = 0u;
  while (sp > 0) {
    KGLOBAL const KBvhNode* n = &s->tlas_nodes[stack[--sp]];
    hit->cost += 1u;
    if (k_ray_box(n, org, inv_d, hit->t) < 0.0f) continue;
    if (n->count == 0u) {
      if (sp + 2 <= K_BVH_STACK) {
        stack[sp++] = n->left_first + 1u;
        stack[sp++] = n->left_first;
      }
      continue;
    }
    for (kuint i = 0u; i < n->count; ++i) {
      kuint instance = n->left_first + i;
      KGLOBAL const KInstance* inst = &s->instances[instance];
      if ((inst->mask & ray_mask) == 0u) continue;
      KVec3 o = xform_point_g(inst->world_to_object, org);
      KVec3 d = xform_vector_g(inst->world_to_object, dir);
      if (k_trace_blas(s, instance, o, d, any_hit, hit, &hit->cost)) {
        found = 1;
        if (any_hit) return 1;
      }
    }
  }
  return found;
}

KFN int k_trace_closest(KTraceCtx* ctx, KVec3 org, KVec3 dir, float tmax, kuint ray_mask, KHit* hit) {
  return k_trace_tlas(ctx, org, dir, tmax, ray_mask, 0, hit);
}

KFN int k_trace_occluded(KTraceCtx* ctx, KVec3 org, KVec3 dir, float tmax, kuint ray_mask) {
  KHit hit;
  return k_trace_tlas(ctx, org, dir, tmax, ray_mask, 1, &hit);
}

#endif
