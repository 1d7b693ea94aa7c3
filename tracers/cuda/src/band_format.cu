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

}  // namespace

void launch_band_to_rgb16f(const float4* band, unsigned short* rgb, size_t pixels, cudaStream_t stream) {
  if (pixels == 0) return;
  constexpr unsigned kThreads = 256;
  const unsigned blocks = static_cast<unsigned>((pixels + kThreads - 1) / kThreads);
  band_to_rgb16f_kernel<<<blocks, kThreads, 0, stream>>>(band, rgb, pixels);
  COHORT_CUDA(cudaGetLastError());
}

}  // namespace cohort::tracers
