/* Skinned characters (MD5 meshes posed by their joints), run by every tracer on its own scene copy: the
 * bind-pose weights live in the tracer once, each frame only the joints travel, and these routines
 * write the skinned vertices and refit the character's BLAS. CUDA and OpenCL run them one work item per
 * vertex (or node); the CPU tracers run them in a host loop over the same functions.
 *
 * The results equal scene::skin_md5 (md5_pose.cpp): position = sum of bias * (R offset + T) over the
 * vertex's weights; normal = the normalised sum of the unit face normals of every triangle touching a
 * vertex at the same position in this pose (R_DeriveTangents; candidates are the triangles at the
 * vertex's bind position, each triangle's face computed once per pose); tangent from the texture derivatives of the vertex's own
 * triangles (scene/tangents.cpp), orthogonalised against the normal. */
#ifndef COHORT_KERNEL_SKINNING_H
#define COHORT_KERNEL_SKINNING_H
#include "layout.h"
#include "vec.h"

/* A skinned BLAS: its vertices [vertex_offset, vertex_offset + vertex_count) of the vertex pool are
 * written from skin vertices [skin_vertex_offset, ...) and joints [joint_offset, joint_offset + joint_count).
 * Its mesh's triangles are [triangle_offset, +triangle_count) of the skin triangle pool (shared by every
 * character of the mesh); each pose writes one KSkinFace per triangle at [face_offset, +triangle_count). */
typedef struct KSkin {
  kuint blas;
  kuint vertex_offset;
  kuint vertex_count;
  kuint skin_vertex_offset;
  kuint joint_offset;
  kuint joint_count;
  kuint triangle_offset;
  kuint triangle_count;
  kuint face_offset;
  kuint pad0, pad1, pad2;
} KSkin;

/* Per skinned vertex: its weights [first_weight, +weight_count) (absolute in the weight pool), and the
 * triangles touching a vertex at its bind position [first_adjacent, +adjacent_count) (absolute in the
 * adjacency pool, whose entries are triangle indices relative to KSkin.triangle_offset). Shared by every
 * skin of one mesh. */
typedef struct KSkinVertex {
  kuint first_weight;
  kuint weight_count;
  kuint first_adjacent;
  kuint adjacent_count;
} KSkinVertex;

typedef struct KSkinWeight {
  float offset[3]; float bias;
  kuint joint;      /* relative to KSkin.joint_offset */
  kuint pad0, pad1, pad2;
} KSkinWeight;

/* A triangle of a skinned mesh by vertex indices relative to KSkin.vertex_offset (its winding as drawn). */
typedef struct KSkinTriangle {
  kuint v0, v1, v2;
  kuint pad;
} KSkinTriangle;

/* What one posed triangle gives the vertices around it: its unit face normal and, when its texture
 * coordinates are not degenerate (has_tangent), its texture-space directions. */
typedef struct KSkinFace {
  float normal[3]; kuint has_tangent;
  float sdir[3]; float pad0;
  float tdir[3]; float pad1;
} KSkinFace;

/* A joint in model space: rotation quaternion (x, y, z, w; column form, v' = q v q*) and position. */
typedef struct KJoint {
  float rotation[4];
  float position[3]; float pad;
} KJoint;

#if defined(__cplusplus) && !defined(__CUDACC_RTC__)
static_assert(sizeof(KSkin) == 48, "KSkin layout");
static_assert(sizeof(KSkinFace) == 48, "KSkinFace layout");
static_assert(sizeof(KSkinVertex) == 16, "KSkinVertex layout");
static_assert(sizeof(KSkinWeight) == 32, "KSkinWeight layout");
static_assert(sizeof(KSkinTriangle) == 16, "KSkinTriangle layout");
static_assert(sizeof(KJoint) == 32, "KJoint layout");
#endif

/* q v q* in the same operation order as glm's quat * vec3, so the host's skin_md5 and this agree. */
KFN KVec3 k_joint_rotate(KGLOBAL const KJoint* j, KVec3 v) {
  KVec3 q = v3(j->rotation[0], j->rotation[1], j->rotation[2]);
  KVec3 uv = v3_cross(q, v);
  KVec3 uuv = v3_cross(q, uv);
  KVec3 s = v3_add(v3_scale(uv, j->rotation[3]), uuv);
  return v3_add(v, v3_scale(s, 2.0f));
}

KFN int k_skin_finite(float x) { return x == x && k_fabs(x) <= 3.402823466e+38f; }

/* Pass 1, vertex i of the skin (0 <= i < vertex_count): its position. */
/* Vertex i of a skin (relative to its vertex_offset) posed by `joints` (the joint pool, any frame's). */
KFN KVec3 k_skinned_point(KGLOBAL const KSkinVertex* skin_vertices, KGLOBAL const KSkinWeight* weights,
                          KGLOBAL const KJoint* joints, KSkin skin, kuint i) {
  KGLOBAL const KSkinVertex* sv = skin_vertices + skin.skin_vertex_offset + i;
  KVec3 p = v3s(0.0f);
  for (kuint w = 0; w < sv->weight_count; ++w) {
    KGLOBAL const KSkinWeight* weight = weights + sv->first_weight + w;
    kuint joint = weight->joint < skin.joint_count ? weight->joint : 0u;
    KGLOBAL const KJoint* j = joints + skin.joint_offset + joint;
    KVec3 moved = v3_add(k_joint_rotate(j, v3_load_g(weight->offset)), v3_load_g(j->position));
    p = v3_add(p, v3_scale(moved, weight->bias));
  }
  return p;
}

KFN void k_skin_position(KGLOBAL KVertex* vertices, KGLOBAL const KSkinVertex* skin_vertices,
                         KGLOBAL const KSkinWeight* weights, KGLOBAL const KJoint* joints, KSkin skin, kuint i) {
  KVec3 p = k_skinned_point(skin_vertices, weights, joints, skin, i);
  KGLOBAL KVertex* out = vertices + skin.vertex_offset + i;
  out->pos[0] = p.x;
  out->pos[1] = p.y;
  out->pos[2] = p.z;
}

KFN KVec3 k_skin_any_perpendicular(KVec3 n) {
  KVec3 helper = k_fabs(n.z) < 0.9f ? v3(0.0f, 0.0f, 1.0f) : v3(1.0f, 0.0f, 0.0f);
  KVec3 t = v3_cross(helper, n);
  float len = v3_length(t);
  return len > 1e-12f ? v3_scale(t, 1.0f / len) : v3(1.0f, 0.0f, 0.0f);
}

KFN int k_skin_same_point(KVec3 a, KVec3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

/* Pass 2, after every position of the skin is written: triangle t's face (0 <= t < triangle_count). */
KFN void k_skin_face(KGLOBAL const KVertex* vertices, KGLOBAL const KSkinTriangle* triangles, KGLOBAL KSkinFace* faces,
                     KSkin skin, kuint t) {
  KGLOBAL const KSkinTriangle* tri = triangles + skin.triangle_offset + t;
  KGLOBAL const KVertex* base = vertices + skin.vertex_offset;
  KGLOBAL const KVertex* va = base + tri->v0;
  KGLOBAL const KVertex* vb = base + tri->v1;
  KGLOBAL const KVertex* vc = base + tri->v2;
  KVec3 p0 = v3_load_g(va->pos), p1 = v3_load_g(vb->pos), p2 = v3_load_g(vc->pos);
  KVec3 face = v3_cross(v3_sub(p2, p0), v3_sub(p1, p0));
  float length = v3_length(face);
  if (length > 0.0f) face = v3(face.x / length, face.y / length, face.z / length);
  KGLOBAL KSkinFace* out = faces + skin.face_offset + t;
  out->normal[0] = face.x;
  out->normal[1] = face.y;
  out->normal[2] = face.z;
  out->has_tangent = 0u;
  KVec3 e1 = v3_sub(p1, p0), e2 = v3_sub(p2, p0);
  float d1x = vb->u - va->u, d1y = vb->v - va->v, d2x = vc->u - va->u, d2y = vc->v - va->v;
  float det = d1x * d2y - d2x * d1y;
  if (!k_skin_finite(det) || k_fabs(det) < 1e-12f) return;
  float r = 1.0f / det;
  KVec3 sdir = v3_scale(v3_sub(v3_scale(e1, d2y), v3_scale(e2, d1y)), r);
  KVec3 tdir = v3_scale(v3_sub(v3_scale(e2, d1x), v3_scale(e1, d2x)), r);
  if (!k_skin_finite(sdir.x + sdir.y + sdir.z + tdir.x + tdir.y + tdir.z)) return;
  out->has_tangent = 1u;
  out->sdir[0] = sdir.x; out->sdir[1] = sdir.y; out->sdir[2] = sdir.z;
  out->tdir[0] = tdir.x; out->tdir[1] = tdir.y; out->tdir[2] = tdir.z;
}

/* Pass 3, after every face: vertex i's normal and tangent. */
KFN void k_skin_normal(KGLOBAL KVertex* vertices, KGLOBAL const KSkinVertex* skin_vertices,
                       KGLOBAL const kuint* adjacency, KGLOBAL const KSkinTriangle* triangles,
                       KGLOBAL const KSkinFace* faces, KSkin skin, kuint i) {
  KGLOBAL const KSkinVertex* sv = skin_vertices + skin.skin_vertex_offset + i;
  KGLOBAL const KVertex* base = vertices + skin.vertex_offset;
  const KVec3 me = v3_load_g(base[i].pos);
  KVec3 normal = v3s(0.0f), tan_s = v3s(0.0f), tan_t = v3s(0.0f);
  for (kuint a = 0; a < sv->adjacent_count; ++a) {
    const kuint t = adjacency[sv->first_adjacent + a];
    KGLOBAL const KSkinTriangle* tri = triangles + skin.triangle_offset + t;
    /* Only a corner at exactly this position counts: vertices that met in the bind pose may part. */
    if (!k_skin_same_point(v3_load_g(base[tri->v0].pos), me) && !k_skin_same_point(v3_load_g(base[tri->v1].pos), me) &&
        !k_skin_same_point(v3_load_g(base[tri->v2].pos), me))
      continue;
    KGLOBAL const KSkinFace* face = faces + skin.face_offset + t;
    normal = v3_add(normal, v3_load_g(face->normal));
    /* The vertex's own triangle: its texture-space directions. */
    if ((tri->v0 != i && tri->v1 != i && tri->v2 != i) || face->has_tangent == 0u) continue;
    tan_s = v3_add(tan_s, v3_load_g(face->sdir));
    tan_t = v3_add(tan_t, v3_load_g(face->tdir));
  }
  float nlen = v3_length(normal);
  normal = nlen > 0.0f ? v3(normal.x / nlen, normal.y / nlen, normal.z / nlen) : v3(0.0f, 0.0f, 1.0f);
  KVec3 tp = v3_sub(tan_s, v3_scale(normal, v3_dot(normal, tan_s)));
  float tlen = v3_length(tp);
  KVec3 tangent = (k_skin_finite(tlen) && tlen > 1e-6f) ? v3(tp.x / tlen, tp.y / tlen, tp.z / tlen)
                                                        : k_skin_any_perpendicular(normal);
  float sign = v3_dot(v3_cross(normal, tangent), tan_t) < 0.0f ? -1.0f : 1.0f;
  KGLOBAL KVertex* out = vertices + skin.vertex_offset + i;
  out->normal[0] = normal.x;
  out->normal[1] = normal.y;
  out->normal[2] = normal.z;
  out->tangent[0] = tangent.x;
  out->tangent[1] = tangent.y;
  out->tangent[2] = tangent.z;
  out->bitangent_sign = sign;
}

/* Refit node i of a BLAS (nodes and triangles of that BLAS, vertices the whole pool) after its vertices
 * moved. Children are stored after their parent, so sweeping i from the last node down to 0 sees every
 * child first; leaves alone can run in parallel. A NaN coordinate leaves a box as it was and an empty
 * child (min > max) adds nothing, as core's refit does. */
KFN void k_refit_grow(float* lo, float* hi, float x, float y, float z) {
  lo[0] = x < lo[0] ? x : lo[0]; hi[0] = x > hi[0] ? x : hi[0];
  lo[1] = y < lo[1] ? y : lo[1]; hi[1] = y > hi[1] ? y : hi[1];
  lo[2] = z < lo[2] ? z : lo[2]; hi[2] = z > hi[2] ? z : hi[2];
}

KFN void k_refit_grow_node(float* lo, float* hi, KGLOBAL const KBvhNode* n) {
  if (n->bmin[0] > n->bmax[0]) return;
  k_refit_grow(lo, hi, n->bmin[0], n->bmin[1], n->bmin[2]);
  k_refit_grow(lo, hi, n->bmax[0], n->bmax[1], n->bmax[2]);
}

KFN void k_refit_blas_node(KGLOBAL KBvhNode* nodes, KGLOBAL const KTriangle* triangles,
                           KGLOBAL const KVertex* vertices, kuint i) {
  KGLOBAL KBvhNode* n = nodes + i;
  float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
  if (n->count > 0u) {
    for (kuint t = n->left_first; t < n->left_first + n->count; ++t) {
      KGLOBAL const KTriangle* tri = triangles + t;
      KGLOBAL const float* a = vertices[tri->v0].pos;
      KGLOBAL const float* b = vertices[tri->v1].pos;
      KGLOBAL const float* c = vertices[tri->v2].pos;
      float tlo[3] = {1e30f, 1e30f, 1e30f}, thi[3] = {-1e30f, -1e30f, -1e30f};
      k_refit_grow(tlo, thi, a[0], a[1], a[2]);
      k_refit_grow(tlo, thi, b[0], b[1], b[2]);
      k_refit_grow(tlo, thi, c[0], c[1], c[2]);
      if (tlo[0] <= thi[0]) {
        k_refit_grow(lo, hi, tlo[0], tlo[1], tlo[2]);
        k_refit_grow(lo, hi, thi[0], thi[1], thi[2]);
      }
    }
  } else {
    k_refit_grow_node(lo, hi, nodes + n->left_first);
    k_refit_grow_node(lo, hi, nodes + n->left_first + 1u);
  }
  n->bmin[0] = lo[0]; n->bmin[1] = lo[1]; n->bmin[2] = lo[2];
  n->bmax[0] = hi[0]; n->bmax[1] = hi[1]; n->bmax[2] = hi[2];
}

#endif
