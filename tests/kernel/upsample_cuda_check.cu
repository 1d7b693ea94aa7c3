// Compile-only check that kernel/upsample.h is valid CUDA (registered by upsample_devices.cmake).
#include "cohort/kernel/upsample.h"

__global__ void demodulate_check(const float* in_rgba, const float* albedo, float* illumination,
                                 KUpsampleParams params) {
  kint x = blockIdx.x * blockDim.x + threadIdx.x, y = blockIdx.y * blockDim.y + threadIdx.y;
  if (x < params.width && y < params.height) k_upsample_demodulate_pixel(in_rgba, albedo, illumination, &params, x, y);
}

__global__ void upsample_check(const float* in_rgba, const float* illumination, const float* depth,
                               const float* normal, const float* albedo, const kuint* id, float* out_rgba,
                               KUpsampleParams params, int method) {
  kint x = blockIdx.x * blockDim.x + threadIdx.x, y = blockIdx.y * blockDim.y + threadIdx.y;
  if (x < params.width && y < params.height)
    k_upsample_pixel(in_rgba, illumination, depth, normal, albedo, id, out_rgba, &params, method, x, y);
}
