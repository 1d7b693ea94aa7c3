#include <cuda_runtime.h>

#include "cuda_check.h"
#include "skinning_launch.h"

namespace cohort::tracers {
namespace {

__global__ void skin_positions_kernel(KVertex* vertices, const KSkinVertex* skin_vertices, const KSkinWeight* weights,
                                      const KJoint* joints, KSkin skin) {
  const kuint i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i < skin.vertex_count) k_skin_position(vertices, skin_vertices, weights, joints, skin, i);
}

__global__ void skin_faces_kernel(const KVertex* vertices, const KSkinTriangle* triangles, KSkinFace* faces, KSkin skin) {
  const kuint t = blockIdx.x * blockDim.x + threadIdx.x;
  if (t < skin.triangle_count) k_skin_face(vertices, triangles, faces, skin, t);
}

__global__ void skin_normals_kernel(KVertex* vertices, SkinBuffers pools, KSkin skin) {
  const kuint i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i < skin.vertex_count)
    k_skin_normal(vertices, pools.skin_vertices, pools.adjacency, pools.triangles, pools.faces, skin, i);
}

__global__ void refit_leaves_kernel(KBvhNode* nodes, const KTriangle* triangles, const KVertex* vertices, kuint count) {
  const kuint i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i < count && nodes[i].count > 0u) k_refit_blas_node(nodes, triangles, vertices, i);
}

__global__ void refit_inner_kernel(KBvhNode* nodes, const KTriangle* triangles, const KVertex* vertices, kuint count) {
  for (kuint n = count; n-- > 0u;)
    if (nodes[n].count == 0u) k_refit_blas_node(nodes, triangles, vertices, n);
}

}  // namespace

void launch_skinning(KVertex* vertices, const SkinBuffers& pools, const KSkin& skin, KBvhNode* blas_nodes,
                     const KTriangle* triangles, const KBlas& blas, cudaStream_t stream) {
  if (skin.vertex_count == 0) return;
  const unsigned block = 128;
  const unsigned vertex_blocks = (skin.vertex_count + block - 1) / block;
  skin_positions_kernel<<<vertex_blocks, block, 0, stream>>>(vertices, pools.skin_vertices, pools.weights, pools.joints,
                                                              skin);
  if (skin.triangle_count > 0)
    skin_faces_kernel<<<(skin.triangle_count + block - 1) / block, block, 0, stream>>>(vertices, pools.triangles,
                                                                                        pools.faces, skin);
  skin_normals_kernel<<<vertex_blocks, block, 0, stream>>>(vertices, pools, skin);
  if (blas.node_count > 0) {
    KBvhNode* nodes = blas_nodes + blas.node_offset;
    const KTriangle* tris = triangles + blas.tri_offset;
    refit_leaves_kernel<<<(blas.node_count + block - 1) / block, block, 0, stream>>>(nodes, tris, vertices, blas.node_count);
    refit_inner_kernel<<<1, 1, 0, stream>>>(nodes, tris, vertices, blas.node_count);
  }
  COHORT_CUDA(cudaGetLastError());
}

}  // namespace cohort::tracers
