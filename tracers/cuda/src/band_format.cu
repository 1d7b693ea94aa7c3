// The band's conversion to half floats on the device, so that RGB16F bands cross the bus at 6 bytes
// a pixel instead of 16 (core/band_buffer.h).
#include <cuda_fp16.h>
#include <cuda_runtime.h>

#include "render_band_launch.h"

namespace cohort::tracers {

namespace {

__global__ void band_to_rgb16f_kernel(const float4* __restrict__ band, unsigned short* __restrict__ rgb, size_t pixels) {
  const size_t p = size_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (p >= pixels) return;
  const float4 c = band[p];
  rgb[3 * p + 0] = __half_as_ushort(__float2half_rn(c.x));
  rgb[3 * p + 1] = __half_as_ushort(__float2half_rn(c.y));
  rgb[3 * p + 2] = __half_as_ushort(__float2half_rn(c.z));
}

__global__ void aux_to_texels_kernel(const KAux* __restrict__ aux, KAuxTexel* __restrict__ texels, size_t pixels) {
  const size_t p = size_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (p >= pixels) return;
  const KAux a = aux[p];
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
  texels[p] = t;
}

}  // namespace

void launch_aux_to_texels(const KAux* aux, KAuxTexel* texels, size_t pixels, cudaStream_t stream) {
  if (pixels == 0) return;
  constexpr unsigned kThreads = 256;
  const unsigned blocks = static_cast<unsigned>((pixels + kThreads - 1) / kThreads);
  aux_to_texels_kernel<<<blocks, kThreads, 0, stream>>>(aux, texels, pixels);
  COHORT_CUDA(cudaGetLastError());
}

void launch_band_to_rgb16f(const float4* band, unsigned short* rgb, size_t pixels, cudaStream_t stream) {
  if (pixels == 0) return;
  constexpr unsigned kThreads = 256;
  const unsigned blocks = static_cast<unsigned>((pixels + kThreads - 1) / kThreads);
  band_to_rgb16f_kernel<<<blocks, kThreads, 0, stream>>>(band, rgb, pixels);
  COHORT_CUDA(cudaGetLastError());
}

}  // namespace cohort::tracers
