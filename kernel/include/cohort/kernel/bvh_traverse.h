/* Two-level BVH traversal over the layouts of layout.h, written once for C++, CUDA and OpenCL C 1.2
 * (portable.h facilities only: KGLOBAL buffers, fixed-size stacks, no recursion, no function pointers).
 *
 * Scene (KSceneRef, geometry only): a TLAS over instances (the KInstance array is in TLAS leaf order)
 * whose leaves name BLASes; a BLAS is a node range and a triangle range in shared buffers (KBlas).
 * Triangle vertex indices are absolute into the vertex buffer. Rays go into object space through
 * world_to_object without renormalising, so t is the same ray parameter in every instance.
 *
 * Queries (mask: instances sharing no bit with it are skipped, e.g. K_MASK_SHADOW for shadow rays):
 *   k_bvh_closest(scene, ctx, o, d, tmin, tmax, mask, &hit)  nearest accepted hit in (tmin, tmax);
 *                                                            hit.triangle is absolute (tri_offset added)
 *   k_bvh_any(scene, ctx, o, d, tmin, tmax, mask)            1 when an accepted hit lies in (tmin, tmax)
 *   k_bvh_shadow(scene, ctx, o, d, tmin, tmax, mask, &T)     T = product of the transmittances of every
 *                                                            surface in (tmin, tmax); returns 1 when T = 0
 * Triangles are hit from both sides (Möller-Trumbore); the integrator decides what facing means. With
 * K_BVH_TRIANGLE_EDGES defined, KSceneRef holds the triangles as KTriangleEdges (parallel to the triangle
 * array) instead of vertices and triangles: a leaf's test is three adjacent loads, not a triangle load and
 * three vertex loads that wait on it (the CUDA build; bit-identical hits).
 * (u, v) weight v1 and v2: p = (1-u-v) p0 + u p1 + v p2.
 *
 * Material hooks, so traversal needs no knowledge of materials. Define before including:
 *   K_BVH_CONTEXT                    type handed to the hooks (pointer or scalar); default int
 *   K_BVH_HIT_PASSES(ctx, instance, triangle, u, v, shadow_ray)
 *        float: 1 when the ray goes through this surface (pass-through, alpha-test miss), 0 when the
 *        hit counts. Used by k_bvh_closest (shadow_ray 0) and k_bvh_any (shadow_ray 1, or 2 when the
 *        mask carries K_RAY_FLAG_FROM_NO_SELF_SHADOW: material.h's k_shadow_ray_kind).
 *        Default 0: every surface counts. Same meaning as material.h's k_hit_transmittance.
 *   K_BVH_SHADOW_TRANSMITTANCE(ctx, instance, triangle, u, v)
 *        KVec3: the fraction of light the surface lets through (0 opaque; tinted glass in between).
 *        Products do not depend on order, so k_bvh_shadow visits surfaces in traversal order and
 *        stops as soon as T reaches 0. Default: v3s(K_BVH_HIT_PASSES(..., 1)).
 *
 * Trees from core/bvh.h are at most K_BVH_MAX_DEPTH levels deep (layout.h); near-child-first
 * traversal pushes at most one node per level, so the stacks below never overflow. */
#ifndef COHORT_KERNEL_BVH_TRAVERSE_H
#define COHORT_KERNEL_BVH_TRAVERSE_H
#include "portable.h"
#include "vec.h"
#include "layout.h"
#include "scene_view.h"

#ifndef K_BVH_CONTEXT
#define K_BVH_CONTEXT int
#endif
#ifndef K_BVH_HIT_PASSES
#define K_BVH_HIT_PASSES(ctx, instance, triangle, u, v, shadow_ray) 0.0f
#endif
#ifndef K_BVH_SHADOW_TRANSMITTANCE
#define K_BVH_SHADOW_TRANSMITTANCE(ctx, instance, triangle, u, v) \
  v3s(K_BVH_HIT_PASSES(ctx, instance, triangle, u, v, 1))
#endif

typedef struct KSceneRef {
#ifdef K_BVH_TRIANGLE_EDGES
  /* The triangles as corners and edges (layout.h's KTriangleEdges), so the walk needs no vertices. */
  KGLOBAL const KTriangleEdges* triangle_edges;
#else
  KGLOBAL const KVertex* vertices;
  KGLOBAL const KTriangle* triangles;
#endif
  KGLOBAL const KBvhNode* blas_nodes;
  KGLOBAL const KBlas* blases;
  KGLOBAL const KInstance* instances;
  KGLOBAL const KBvhNode* tlas_nodes;
  kuint instance_count;
  kuint tlas_node_count;
} KSceneRef;

#define K_BVH_QUERY_CLOSEST 0
#define K_BVH_QUERY_ANY 1
#define K_BVH_QUERY_SHADOW 2

/* A ray in one space with the reciprocal direction for slab tests; o_inv_d = o * inv_d turns each
 * slab distance into one multiply-add. */
typedef struct KBvhRay {
  KVec3 o, d, inv_d, o_inv_d;
} KBvhRay;

KFN float k_bvh_safe_inverse(float x) {
  /* 1/0 = inf meets 0 * inf = NaN when the origin lies on a slab plane; a huge finite value does not. */
  if (k_fabs(x) < 1e-30f) return x >= 0.0f ? 1e30f : -1e30f;
  return 1.0f / x;
}

KFN KBvhRay k_bvh_make_ray(KVec3 o, KVec3 d) {
  KBvhRay r;
  r.o = o;
  r.d = d;
  r.inv_d = v3(k_bvh_safe_inverse(d.x), k_bvh_safe_inverse(d.y), k_bvh_safe_inverse(d.z));
  r.o_inv_d = v3_mul(o, r.inv_d);
  return r;
}

/* A node as two 16-byte loads: its box, and where its children or primitives start (count 0: an
 * interior node whose two children sit at left_first and left_first + 1). */
typedef struct KBvhNodeData {
  KVec3 bmin, bmax;
  kuint left_first, count;
} KBvhNodeData;

KFN KBvhNodeData k_bvh_load_node(KGLOBAL const KBvhNode* n) {
  KFloat4 lo = k_load4((KGLOBAL const float*)n);
  KFloat4 hi = k_load4((KGLOBAL const float*)n + 4);
  KBvhNodeData d;
  d.bmin = v3(lo.x, lo.y, lo.z);
  d.bmax = v3(hi.x, hi.y, hi.z);
  d.left_first = k_as_uint(lo.w);
  d.count = k_as_uint(hi.w);
  return d;
}

/* Entry distance into the box clipped to [tmin, tmax], or K_INF when the ray misses it. */
KFN float k_bvh_ray_box(KBvhRay r, KVec3 bmin, KVec3 bmax, float tmin, float tmax) {
  float tx1 = bmin.x * r.inv_d.x - r.o_inv_d.x, tx2 = bmax.x * r.inv_d.x - r.o_inv_d.x;
  float ty1 = bmin.y * r.inv_d.y - r.o_inv_d.y, ty2 = bmax.y * r.inv_d.y - r.o_inv_d.y;
  float tz1 = bmin.z * r.inv_d.z - r.o_inv_d.z, tz2 = bmax.z * r.inv_d.z - r.o_inv_d.z;
  float tnear = k_fmax(k_fmax(k_fmin(tx1, tx2), k_fmin(ty1, ty2)), k_fmax(k_fmin(tz1, tz2), tmin));
  float tfar = k_fmin(k_fmin(k_fmax(tx1, tx2), k_fmax(ty1, ty2)), k_fmin(k_fmax(tz1, tz2), tmax));
  return tnear <= tfar ? tnear : K_INF;
}

/* An interior node whose children start at `left`: pushes the far child when the ray enters both (the
 * stack holds one entry per level, so it cannot overflow) and makes the nearer one current, already
 * loaded. 0 when the ray misses both: pop. */
KFN int k_bvh_descend(KBvhRay r, KGLOBAL const KBvhNode* nodes, kuint left, float tmin, float tmax, kuint* stack,
                      int* sp, KBvhNodeData* current) {
  KBvhNodeData a = k_bvh_load_node(nodes + left);
  KBvhNodeData b = k_bvh_load_node(nodes + left + 1u);
  float ta = k_bvh_ray_box(r, a.bmin, a.bmax, tmin, tmax);
  float tb = k_bvh_ray_box(r, b.bmin, b.bmax, tmin, tmax);
  int b_first = tb < ta;
  float t_near = b_first ? tb : ta, t_far = b_first ? ta : tb;
  if (t_near == K_INF) return 0;
  if (t_far != K_INF && *sp < K_BVH_MAX_DEPTH) stack[(*sp)++] = b_first ? left : left + 1u;
  *current = b_first ? b : a;
  return 1;
}

/* The next pushed node the ray still enters (a closer hit found since the push can rule nodes out);
 * 0 when the stack is empty. */
KFN int k_bvh_pop(KBvhRay r, KGLOBAL const KBvhNode* nodes, float tmin, float tmax, const kuint* stack, int* sp,
                  KBvhNodeData* current) {
  while (*sp > 0) {
    KBvhNodeData n = k_bvh_load_node(nodes + stack[--(*sp)]);
    if (k_bvh_ray_box(r, n.bmin, n.bmax, tmin, tmax) != K_INF) {
      *current = n;
      return 1;
    }
  }
  return 0;
}

/* Möller-Trumbore, both-sided, from the first corner and the edges to the other two (e1 = p1 - p0,
 * e2 = p2 - p0): 1 and (t, u, v) when tmin < t < tmax. */
KFN int k_bvh_ray_triangle_edges(KVec3 o, KVec3 d, KVec3 p0, KVec3 e1, KVec3 e2, float tmin, float tmax,
                                 float* t_out, float* u_out, float* v_out) {
  KVec3 p = v3_cross(d, e2);
  float det = v3_dot(e1, p);
  if (k_fabs(det) < 1e-20f) return 0;
  float inv_det = 1.0f / det;
  KVec3 s = v3_sub(o, p0);
  float u = v3_dot(s, p) * inv_det;
  if (u < 0.0f || u > 1.0f) return 0;
  KVec3 q = v3_cross(s, e1);
  float v = v3_dot(d, q) * inv_det;
  if (v < 0.0f || u + v > 1.0f) return 0;
  float t = v3_dot(e2, q) * inv_det;
  if (!(t > tmin && t < tmax)) return 0;
  *t_out = t;
  *u_out = u;
  *v_out = v;
  return 1;
}

KFN int k_bvh_ray_triangle(KVec3 o, KVec3 d, KVec3 p0, KVec3 p1, KVec3 p2, float tmin, float tmax,
                           float* t_out, float* u_out, float* v_out) {
  return k_bvh_ray_triangle_edges(o, d, p0, v3_sub(p1, p0), v3_sub(p2, p0), tmin, tmax, t_out, u_out, v_out);
}

#ifndef K_BVH_TRIANGLE_EDGES
/* A vertex position: the first three floats of its 16-byte-aligned KVertex. */
KFN KVec3 k_bvh_vertex_position(KSceneRef scene, kuint vertex) {
  KFloat4 p = k_load4((KGLOBAL const float*)(scene.vertices + vertex));
  return v3(p.x, p.y, p.z);
}
#endif

/* The same edges as k_bvh_ray_triangle subtracts (so the same hits, bit for bit), for KTriangleEdges. */
KFN void k_triangle_edges_write(KGLOBAL KTriangleEdges* out, KGLOBAL const KVertex* vertices, KTriangle tri) {
  KGLOBAL const float* p0 = vertices[tri.v0].pos;
  KGLOBAL const float* p1 = vertices[tri.v1].pos;
  KGLOBAL const float* p2 = vertices[tri.v2].pos;
  for (int a = 0; a < 3; ++a) {
    out->p0[a] = p0[a];
    out->e1[a] = p1[a] - p0[a];
    out->e2[a] = p2[a] - p0[a];
  }
  out->pad0 = out->pad1 = out->pad2 = 0.0f;
}

KFN int k_bvh_hit_triangle(KSceneRef scene, kuint triangle, KVec3 o, KVec3 d, float tmin, float tmax,
                           float* t, float* u, float* v) {
#ifdef K_BVH_TRIANGLE_EDGES
  KGLOBAL const float* e = (KGLOBAL const float*)(scene.triangle_edges + triangle);
  KFloat4 a = k_load4(e), b = k_load4(e + 4), c = k_load4(e + 8);
  return k_bvh_ray_triangle_edges(o, d, v3(a.x, a.y, a.z), v3(b.x, b.y, b.z), v3(c.x, c.y, c.z), tmin, tmax, t, u, v);
#else
  KFloat4 tri = k_load4((KGLOBAL const float*)(scene.triangles + triangle));
  return k_bvh_ray_triangle(o, d, k_bvh_vertex_position(scene, k_as_uint(tri.x)),
                            k_bvh_vertex_position(scene, k_as_uint(tri.y)),
                            k_bvh_vertex_position(scene, k_as_uint(tri.z)), tmin, tmax, t, u, v);
#endif
}

/* One candidate hit. CLOSEST records it and shrinks *tmax; ANY reports it; SHADOW multiplies it
 * into *transmittance. Returns 1 when the whole query is decided. */
KFN int k_bvh_accept(K_BVH_CONTEXT ctx, int query, int shadow_ray, kuint instance, kuint triangle, float t, float u,
                     float v, float* tmax, KHit* hit, KVec3* transmittance) {
  if (query == K_BVH_QUERY_SHADOW) {
    KVec3 through = K_BVH_SHADOW_TRANSMITTANCE(ctx, instance, triangle, u, v);
    *transmittance = v3_mul(*transmittance, through);
    return v3_max_component(*transmittance) <= 0.0f;
  }
  if (K_BVH_HIT_PASSES(ctx, instance, triangle, u, v, shadow_ray) > 0.0f) return 0;
  if (query == K_BVH_QUERY_ANY) return 1;
  *tmax = t;
  hit->t = t;
  hit->u = u;
  hit->v = v;
  hit->instance = instance;
  hit->triangle = triangle;
  return 0;
}

/* Walks one instance's BLAS with the object-space ray. */
KFN int k_bvh_traverse_blas(KSceneRef scene, K_BVH_CONTEXT ctx, int query, int shadow_ray, kuint instance, KBvhRay r,
                            float tmin, float* tmax, KHit* hit, kuint* cost, KVec3* transmittance) {
  KGLOBAL const KBlas* blas = scene.blases + scene.instances[instance].blas;
  if (blas->node_count == 0u) return 0;
  KGLOBAL const KBvhNode* nodes = scene.blas_nodes + blas->node_offset;
  kuint tri_offset = blas->tri_offset;
  kuint stack[K_BVH_MAX_DEPTH];
  int sp = 0;
  KBvhNodeData n = k_bvh_load_node(nodes);
  if (k_bvh_ray_box(r, n.bmin, n.bmax, tmin, *tmax) == K_INF) return 0;
  for (;;) {
    *cost += 1u;
    if (n.count > 0u) {
      kuint end = n.left_first + n.count;
      for (kuint i = n.left_first; i < end; ++i) {
        kuint triangle = tri_offset + i;
        float t, u, v;
        if (!k_bvh_hit_triangle(scene, triangle, r.o, r.d, tmin, *tmax, &t, &u, &v)) continue;
        if (k_bvh_accept(ctx, query, shadow_ray, instance, triangle, t, u, v, tmax, hit, transmittance)) return 1;
      }
    } else if (k_bvh_descend(r, nodes, n.left_first, tmin, *tmax, stack, &sp, &n)) {
      continue;
    }
    if (!k_bvh_pop(r, nodes, tmin, *tmax, stack, &sp, &n)) return 0;
  }
}

/* The instance's world-to-object rows, three 16-byte loads (KInstance keeps them 16-byte aligned). */
KFN KBvhRay k_bvh_object_ray(KGLOBAL const KInstance* inst, KVec3 o, KVec3 d) {
  KFloat4 r0 = k_load4(inst->world_to_object), r1 = k_load4(inst->world_to_object + 4);
  KFloat4 r2 = k_load4(inst->world_to_object + 8);
  KVec3 oo = v3(r0.x * o.x + r0.y * o.y + r0.z * o.z + r0.w, r1.x * o.x + r1.y * o.y + r1.z * o.z + r1.w,
                r2.x * o.x + r2.y * o.y + r2.z * o.z + r2.w);
  KVec3 od = v3(r0.x * d.x + r0.y * d.y + r0.z * d.z, r1.x * d.x + r1.y * d.y + r1.z * d.z,
                r2.x * d.x + r2.y * d.y + r2.z * d.z);
  return k_bvh_make_ray(oo, od);
}

/* Walks the TLAS; per instance leaf whose mask matches, the instance's BLAS in object space. The hit,
 * step count and transmittance live in locals until the end: the caller's copies are behind pointers
 * into a called function, which on the GPU would mean a local-memory store per step. */
KFN_OUTLINED int k_bvh_traverse(KSceneRef scene, K_BVH_CONTEXT ctx, int query, KVec3 o, KVec3 d, float tmin, float tmax,
                       kuint mask, KHit* hit_out, KVec3* transmittance_out) {
  KHit hit;
  hit.t = tmax;
  hit.u = 0.0f;
  hit.v = 0.0f;
  hit.instance = K_NONE;
  hit.triangle = K_NONE;
  hit.cost = 0u;
  hit.pad0 = 0u;
  hit.pad1 = 0u;
  kuint cost = 0u;
  KVec3 transmittance = *transmittance_out;
  int decided = 0;
  if (scene.tlas_node_count > 0u && scene.instance_count > 0u) {
    /* The hooks' ray kind: 0 closest (camera, bounce), 1 occlusion, 2 occlusion from a noSelfShadow surface. */
    int shadow_ray = query == K_BVH_QUERY_CLOSEST ? 0 : ((mask & K_RAY_FLAG_FROM_NO_SELF_SHADOW) ? 2 : 1);
    KBvhRay world = k_bvh_make_ray(o, d);
    kuint stack[K_BVH_MAX_DEPTH];
    int sp = 0;
    KBvhNodeData n = k_bvh_load_node(scene.tlas_nodes);
    int alive = k_bvh_ray_box(world, n.bmin, n.bmax, tmin, tmax) != K_INF;
    while (alive) {
      cost += 1u;
      if (n.count > 0u) {
        kuint end = n.left_first + n.count;
        for (kuint i = n.left_first; i < end && !decided; ++i) {
          KGLOBAL const KInstance* inst = scene.instances + i;
          if ((inst->mask & mask) == 0u) continue;
          decided = k_bvh_traverse_blas(scene, ctx, query, shadow_ray, i, k_bvh_object_ray(inst, o, d), tmin, &tmax,
                                        &hit, &cost, &transmittance);
        }
        if (decided) break;
      } else if (k_bvh_descend(world, scene.tlas_nodes, n.left_first, tmin, tmax, stack, &sp, &n)) {
        continue;
      }
      alive = k_bvh_pop(world, scene.tlas_nodes, tmin, tmax, stack, &sp, &n);
    }
  }
  hit.cost = cost;
  *hit_out = hit;
  *transmittance_out = transmittance;
  return decided;
}

KFN int k_bvh_closest(KSceneRef scene, K_BVH_CONTEXT ctx, KVec3 o, KVec3 d, float tmin, float tmax, kuint mask,
                      KHit* hit) {
  KVec3 unused = v3s(1.0f);
  k_bvh_traverse(scene, ctx, K_BVH_QUERY_CLOSEST, o, d, tmin, tmax, mask, hit, &unused);
  return hit->instance != K_NONE;
}

KFN int k_bvh_any(KSceneRef scene, K_BVH_CONTEXT ctx, KVec3 o, KVec3 d, float tmin, float tmax, kuint mask) {
  KHit scratch;
  KVec3 unused = v3s(1.0f);
  return k_bvh_traverse(scene, ctx, K_BVH_QUERY_ANY, o, d, tmin, tmax, mask, &scratch, &unused);
}

KFN int k_bvh_shadow(KSceneRef scene, K_BVH_CONTEXT ctx, KVec3 o, KVec3 d, float tmin, float tmax, kuint mask,
                     KVec3* transmittance) {
  KHit scratch;
  *transmittance = v3s(1.0f);
  if (k_bvh_traverse(scene, ctx, K_BVH_QUERY_SHADOW, o, d, tmin, tmax, mask, &scratch, transmittance)) {
    *transmittance = v3s(0.0f);
    return 1;
  }
  return 0;
}

#endif
