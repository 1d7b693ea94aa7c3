/* Skinned characters on an OpenCL device (kernel/skinning.h): one work item per vertex for the positions,
 * then one per triangle for its face, then one per vertex for the normals; the BLAS refit runs its leaves one work item each, then one work item sweeps the
 * inner nodes bottom-up. The host enqueues them in order on its in-order queue. */
#include "cohort/kernel/skinning.h"

__kernel void cohort_skin_positions(__global KVertex* vertices, __global const KSkinVertex* skin_vertices,
                                    __global const KSkinWeight* weights, __global const KJoint* joints,
                                    __global const KSkin* skins, uint skin_index) {
  KSkin skin = skins[skin_index];
  kuint i = (kuint)get_global_id(0);
  if (i < skin.vertex_count) k_skin_position(vertices, skin_vertices, weights, joints, skin, i);
}

__kernel void cohort_skin_faces(__global const KVertex* vertices, __global const KSkinTriangle* triangles,
                                __global KSkinFace* faces, __global const KSkin* skins, uint skin_index) {
  KSkin skin = skins[skin_index];
  kuint t = (kuint)get_global_id(0);
  if (t < skin.triangle_count) k_skin_face(vertices, triangles, faces, skin, t);
}

__kernel void cohort_skin_normals(__global KVertex* vertices, __global const KSkinVertex* skin_vertices,
                                  __global const uint* adjacency, __global const KSkinTriangle* triangles,
                                  __global const KSkinFace* faces, __global const KSkin* skins, uint skin_index) {
  KSkin skin = skins[skin_index];
  kuint i = (kuint)get_global_id(0);
  if (i < skin.vertex_count) k_skin_normal(vertices, skin_vertices, adjacency, triangles, faces, skin, i);
}

__kernel void cohort_refit_blas_leaves(__global KBvhNode* blas_nodes, __global const KTriangle* triangles,
                                       __global const KVertex* vertices, __global const KBlas* blases,
                                       __global const KSkin* skins, uint skin_index) {
  KBlas blas = blases[skins[skin_index].blas];
  kuint n = (kuint)get_global_id(0);
  if (n < blas.node_count && blas_nodes[blas.node_offset + n].count > 0u)
    k_refit_blas_node(blas_nodes + blas.node_offset, triangles + blas.tri_offset, vertices, n);
}

__kernel void cohort_refit_blas(__global KBvhNode* blas_nodes, __global const KTriangle* triangles,
                                __global const KVertex* vertices, __global const KBlas* blases,
                                __global const KSkin* skins, uint skin_index) {
  if (get_global_id(0) != 0) return;
  KBlas blas = blases[skins[skin_index].blas];
  for (kuint n = blas.node_count; n-- > 0u;)
    if (blas_nodes[blas.node_offset + n].count == 0u)
      k_refit_blas_node(blas_nodes + blas.node_offset, triangles + blas.tri_offset, vertices, n);
}
