// The band's conversion to half floats or RGB9E5 words on the device, so that packed bands cross the
// bus at 6 or 4 bytes a pixel instead of 16 (core/band_buffer.h, kernel/band_pack.h).
#include <cuda_fp16.h>
#include <cuda_runtime.h>

#include "cohort/kernel/band_pack.h"
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

__global__ void band_to_rgb9e5_kernel(const float4* __restrict__ band, kuint* __restrict__ packed, size_t pixels,
                                      kuint first_pixel, kuint frame) {
  const size_t p = size_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (p >= pixels) return;
  const float4 c = band[p];
  packed[p] = k_rgb9e5_encode(c.x, c.y, c.z, k_rgb9e5_dither(first_pixel + kuint(p), frame));
}

}  // namespace

void launch_band_to_rgb16f(const float4* band, unsigned short* rgb, size_t pixels, cudaStream_t stream) {
  if (pixels == 0) return;
  constexpr unsigned kThreads = 256;
  const unsigned blocks = static_cast<unsigned>((pixels + kThreads - 1) / kThreads);
  band_to_rgb16f_kernel<<<blocks, kThreads, 0, stream>>>(band, rgb, pixels);
  COHORT_CUDA(cudaGetLastError());
}

void launch_band_to_rgb9e5(const float4* band, unsigned* packed, size_t pixels, unsigned first_pixel, unsigned frame,
                           cudaStream_t stream) {
  if (pixels == 0) return;
  constexpr unsigned kThreads = 256;
  const unsigned blocks = static_cast<unsigned>((pixels + kThreads - 1) / kThreads);
  band_to_rgb9e5_kernel<<<blocks, kThreads, 0, stream>>>(band, packed, pixels, first_pixel, frame);
  COHORT_CUDA(cudaGetLastError());
}

}  // namespace cohort::tracers
