// CUDA entry point: one thread per pixel of the band, running the shared integrator over the portable
// two-level BVH, exactly as the OpenCL kernel does. Texels are read through a texture object (the
// read-only texture cache); everything else through plain global loads.
#include <cuda_fp16.h>
#include <cuda_runtime.h>

#define K_CUDA_DEVICE_ONLY 1
#define K_BVH_TRIANGLE_EDGES 1  // leaves read KTriangleEdges (CudaTracer keeps them with the triangles)
__constant__ cudaTextureObject_t cohort_texel_texture;
#define K_TEXEL_LOAD(texels, index) tex1Dfetch<unsigned int>(cohort_texel_texture, (int)(index))

#include "cohort/kernel/trace_bvh.h"
#include "cohort/kernel/integrator.h"
#include "cohort/kernel/aux_outputs.h"
#include "render_band_launch.h"

namespace cohort::tracers {

// At least 4 blocks of 128 threads per SM: caps the kernel at 128 registers (25% occupancy) instead of
// 164. Measured on one H100 (docs/integrator.md, "CUDA kernel shape"): 3 blocks 15.8 ms, 4 blocks 13.7 ms,
// 5-6 blocks 13.2-13.4 ms on the large map at 1080p but slower on the test map, where spills cost more.
// Two builds: with every pixel tracing paths the sparse pattern's test is compiled out, since in this
// 128-register kernel even that early exit cost 1.5-2% of a full frame (nvidia-h100-x1, docs/integrator.md).
// kFirstHit: the first sample's first surface is recorded for the aux planes (K_AUX_PATH_FIRST_HIT), a
// build of its own so that the kernel without it stays as it was.
template <bool kSparse, bool kFirstHit>
__global__ void __launch_bounds__(128, 4) render_band_kernel(KSceneView scene, KFrameParams params, KCamera camera,
                                                          float4* band, unsigned long long* ray_counts,
                                                          unsigned* row_rays, KPathFirstHit* first_hits) {
  const kuint x = blockIdx.x * blockDim.x + threadIdx.x;
  const kuint row = blockIdx.y * blockDim.y + threadIdx.y;
  const kuint y = params.row_begin + row;
  const bool inside = x < camera.width && y < params.row_end;
  KTraceCtx ctx;
  ctx.scene = scene;
  ctx.closest_rays = 0u;
  ctx.occlusion_rays = 0u;
  if (inside) {
    KVec3 c = kSparse ? k_render_pixel(&ctx, &params, &camera, x, y)
                      : k_render_pixel_paths(&ctx, &params, &camera, x, y,
                                             kFirstHit ? first_hits + size_t(row) * camera.width + x : nullptr);
    band[size_t(row) * camera.width + x] = make_float4(c.x, c.y, c.z, 1.0f);
  }
  if (ray_counts) {
    // One atomic per warp: the whole warp reaches here, inside the image or not.
    unsigned closest = __reduce_add_sync(0xffffffffu, ctx.closest_rays);
    unsigned occlusion = __reduce_add_sync(0xffffffffu, ctx.occlusion_rays);
    if ((threadIdx.x + threadIdx.y * blockDim.x) % 32u == 0u) {
      atomicAdd(&ray_counts[0], (unsigned long long)closest);
      atomicAdd(&ray_counts[1], (unsigned long long)occlusion);
    }
  }
  if (row_rays) {
    // Rays per row of the band (the balancer's per-row work). With 16-wide blocks a warp holds two
    // rows: lanes 0-15 one, 16-31 the next; each half adds once.
    const unsigned mine = inside ? ctx.closest_rays + ctx.occlusion_rays : 0u;
    const unsigned lane = (threadIdx.x + threadIdx.y * blockDim.x) % 32u;
    const unsigned low = __reduce_add_sync(0xffffffffu, lane < 16u ? mine : 0u);
    const unsigned high = __reduce_add_sync(0xffffffffu, lane >= 16u ? mine : 0u);
    const unsigned half = lane < 16u ? low : high;
    if ((lane == 0u || lane == 16u) && y < params.row_end && half != 0u) atomicAdd(&row_rays[row], half);
  }
}

// The 32-byte texel the host's BandBuffer keeps (halves for normal and albedo).
__device__ void store_aux_texel(const KAux& a, KAuxTexel* out) {
  KAuxTexel t;
  t.depth = a.depth;
  t.prev_depth = a.prev_depth;
  t.motion[0] = a.motion[0];
  t.motion[1] = a.motion[1];
  for (int k = 0; k < 3; ++k) {
    t.normal[k] = __half_as_ushort(__float2half_rn(a.normal[k]));
    t.albedo[k] = __half_as_ushort(__float2half_rn(a.albedo[k]));
  }
  t.id = a.id;
  *out = t;
}

// Auxiliary outputs (aux_outputs.h), launched only for frames that ask for them: K_AUX_CENTRE_RAY, a ray
// of their own through each pixel's centre.
__global__ void aux_band_kernel(KSceneView scene, KFrameParams params, KCamera camera, KCamera previous_camera,
                                KAuxHistory history, KAuxTexel* band_aux) {
  const kuint x = blockIdx.x * blockDim.x + threadIdx.x;
  const kuint row = blockIdx.y * blockDim.y + threadIdx.y;
  const kuint y = params.row_begin + row;
  if (x >= camera.width || y >= params.row_end) return;
  KTraceCtx ctx;
  ctx.scene = scene;
  ctx.closest_rays = 0u;
  ctx.occlusion_rays = 0u;
  KAux a;
  k_pixel_aux(&ctx, &camera, &previous_camera, &history, x, y, &a);
  store_aux_texel(a, band_aux + size_t(row) * camera.width + x);
}

// K_AUX_PATH_FIRST_HIT: the planes finished from what the band's paths recorded (no ray of their own).
__global__ void aux_from_first_hits_kernel(KSceneView scene, KFrameParams params, KCamera camera,
                                           KCamera previous_camera, KAuxHistory history,
                                           const KPathFirstHit* first_hits, KAuxTexel* band_aux) {
  const kuint x = blockIdx.x * blockDim.x + threadIdx.x;
  const kuint row = blockIdx.y * blockDim.y + threadIdx.y;
  const kuint y = params.row_begin + row;
  if (x >= camera.width || y >= params.row_end) return;
  const size_t p = size_t(row) * camera.width + x;
  KAux a;
  k_aux_from_first_hit(&scene, &params, &camera, &previous_camera, &history, x, y, first_hits[p], &a);
  store_aux_texel(a, band_aux + p);
}

void launch_aux_band(const KSceneView& scene, const KFrameParams& params, const KCamera& camera,
                     const KCamera& previous_camera, const KAuxHistory& history, KAuxTexel* band_aux,
                     cudaStream_t stream) {
  const kuint rows = params.row_end - params.row_begin;
  const dim3 block(16, 8);
  const dim3 grid((camera.width + block.x - 1) / block.x, (rows + block.y - 1) / block.y);
  aux_band_kernel<<<grid, block, 0, stream>>>(scene, params, camera, previous_camera, history, band_aux);
  COHORT_CUDA(cudaGetLastError());
}

void launch_aux_from_first_hits(const KSceneView& scene, const KFrameParams& params, const KCamera& camera,
                                const KCamera& previous_camera, const KAuxHistory& history,
                                const KPathFirstHit* first_hits, KAuxTexel* band_aux, cudaStream_t stream) {
  const kuint rows = params.row_end - params.row_begin;
  const dim3 block(16, 8);
  const dim3 grid((camera.width + block.x - 1) / block.x, (rows + block.y - 1) / block.y);
  aux_from_first_hits_kernel<<<grid, block, 0, stream>>>(scene, params, camera, previous_camera, history, first_hits,
                                                         band_aux);
  COHORT_CUDA(cudaGetLastError());
}

void set_texel_texture(cudaTextureObject_t texture) {
  COHORT_CUDA(cudaMemcpyToSymbol(cohort_texel_texture, &texture, sizeof texture));
}

void launch_render_band(const KSceneView& scene, const KFrameParams& params, const KCamera& camera, float4* band,
                        unsigned long long* ray_counts, unsigned* row_rays, KPathFirstHit* first_hits,
                        cudaStream_t stream) {
  const kuint rows = params.row_end - params.row_begin;
  const dim3 block(16, 8);  // 16 wide: the row ray counts rely on two rows per warp
  const dim3 grid((camera.width + block.x - 1) / block.x, (rows + block.y - 1) / block.y);
  const bool sparse = params.path_pixels != 0u && params.path_pixels < K_PATH_PATTERN_PIXELS;
  if (sparse)
    render_band_kernel<true, false><<<grid, block, 0, stream>>>(scene, params, camera, band, ray_counts, row_rays, nullptr);
  else if (first_hits)
    render_band_kernel<false, true><<<grid, block, 0, stream>>>(scene, params, camera, band, ray_counts, row_rays,
                                                                first_hits);
  else
    render_band_kernel<false, false><<<grid, block, 0, stream>>>(scene, params, camera, band, ray_counts, row_rays,
                                                                 nullptr);
  COHORT_CUDA(cudaGetLastError());
}

}  // namespace cohort::tracers
