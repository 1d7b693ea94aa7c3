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

__global__ void refit_parents_kernel(const KBvhNode* nodes, kuint count, RefitScratch scratch) {
  const kuint i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= count) return;
  scratch.arrivals[i] = 0u;
  if (nodes[i].count == 0u) {
    scratch.parent[nodes[i].left_first] = i;
    scratch.parent[nodes[i].left_first + 1u] = i;
  }
}

// An inner node's box from its children's, read past L1: another thread (maybe on another SM) wrote
// them, and only L2 is coherent.
__device__ void refit_inner_node(KBvhNode* nodes, kuint i) {
  KBvhNode* n = nodes + i;
  float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
  for (kuint c = 0; c < 2u; ++c) {
    const KBvhNode* child = nodes + n->left_first + c;
    float cmin[3], cmax[3];
    for (int k = 0; k < 3; ++k) cmin[k] = __ldcg(child->bmin + k), cmax[k] = __ldcg(child->bmax + k);
    if (cmin[0] > cmax[0]) continue;
    k_refit_grow(lo, hi, cmin[0], cmin[1], cmin[2]);
    k_refit_grow(lo, hi, cmax[0], cmax[1], cmax[2]);
  }
  for (int k = 0; k < 3; ++k) n->bmin[k] = lo[k], n->bmax[k] = hi[k];
}

__global__ void refit_upward_kernel(KBvhNode* nodes, const KTriangle* triangles, const KVertex* vertices, kuint count,
                                    RefitScratch scratch) {
  const kuint i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= count || nodes[i].count == 0u) return;
  k_refit_blas_node(nodes, triangles, vertices, i);
  for (kuint n = i; n != 0u;) {
    __threadfence();  // this node's box is in L2 before the sibling's thread can see the arrival
    const kuint parent = scratch.parent[n];
    if (parent == K_NONE) return;  // a node no inner node points at (the root has no parent)
    if (atomicAdd(scratch.arrivals + parent, 1u) == 0u) return;  // the sibling is not done: its thread goes on
    __threadfence();
    refit_inner_node(nodes, parent);
    n = parent;
  }
}

__global__ void triangle_edges_kernel(KTriangleEdges* edges, const KTriangle* triangles, const KVertex* vertices,
                                      size_t first, size_t count) {
  const size_t i = size_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i < count) k_triangle_edges_write(edges + first + i, vertices, triangles[first + i]);
}

}  // namespace

void launch_triangle_edges(KTriangleEdges* edges, const KTriangle* triangles, const KVertex* vertices, size_t first,
                           size_t count, cudaStream_t stream) {
  if (count == 0 || !edges) return;
  const unsigned block = 128;
  triangle_edges_kernel<<<unsigned((count + block - 1) / block), block, 0, stream>>>(edges, triangles, vertices, first,
                                                                                     count);
  COHORT_CUDA(cudaGetLastError());
}

void launch_skinning(KVertex* vertices, const SkinBuffers& pools, const KSkin& skin, KBvhNode* blas_nodes,
                     const KTriangle* triangles, KTriangleEdges* edges, const KBlas& blas, const RefitScratch& scratch,
                     cudaStream_t stream) {
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
    const unsigned node_blocks = (blas.node_count + block - 1) / block;
    COHORT_CUDA(cudaMemsetAsync(scratch.parent, 0xFF, blas.node_count * sizeof(kuint), stream));
    refit_parents_kernel<<<node_blocks, block, 0, stream>>>(nodes, blas.node_count, scratch);
    refit_upward_kernel<<<node_blocks, block, 0, stream>>>(nodes, tris, vertices, blas.node_count, scratch);
  }
  launch_triangle_edges(edges, triangles, vertices, blas.tri_offset, blas.tri_count, stream);
  COHORT_CUDA(cudaGetLastError());
}

}  // namespace cohort::tracers
