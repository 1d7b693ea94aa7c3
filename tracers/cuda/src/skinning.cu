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

__global__ void skin_normals_kernel(KVertex* vertices, const KSkinVertex* skin_vertices, const KSkinTriangle* adjacency,
                                    KSkin skin) {
  const kuint i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i < skin.vertex_count) k_skin_normal(vertices, skin_vertices, adjacency, skin, i);
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

void launch_skinning(KVertex* vertices, const KSkinVertex* skin_vertices, const KSkinWeight* weights,
                     const KSkinTriangle* adjacency, const KJoint* joints, const KSkin& skin, KBvhNode* blas_nodes,
                     const KTriangle* triangles, const KBlas& blas, cudaStream_t stream) {
  if (skin.vertex_count == 0) return;
  const unsigned block = 128;
  skin_positions_kernel<<<(skin.vertex_count + block - 1) / block, block, 0, stream>>>(vertices, skin_vertices, weights,
                                                                                     joints, skin);
  skin_normals_kernel<<<(skin.vertex_count + block - 1) / block, block, 0, stream>>>(vertices, skin_vertices, adjacency,
                                                                                   skin);
  if (blas.node_count > 0) {
    KBvhNode* nodes = blas_nodes + blas.node_offset;
    const KTriangle* tris = triangles + blas.tri_offset;
    refit_leaves_kernel<<<(blas.node_count + block - 1) / block, block, 0, stream>>>(nodes, tris, vertices, blas.node_count);
    refit_inner_kernel<<<1, 1, 0, stream>>>(nodes, tris, vertices, blas.node_count);
  }
  COHORT_CUDA(cudaGetLastError());
}

}  // namespace cohort::tracers
