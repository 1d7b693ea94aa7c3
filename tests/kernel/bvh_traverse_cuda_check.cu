// Compile-only check that kernel/bvh_traverse.h is valid CUDA (registered by bvh_traverse_devices.cmake).
#include "cohort/kernel/bvh_traverse.h"

__global__ void bvh_traverse_check(KSceneRef scene, const float* rays, int count, KHit* hits, int* occluded,
                                   KVec3* transmittance) {
  int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= count) return;
  KVec3 o = v3(rays[8 * i], rays[8 * i + 1], rays[8 * i + 2]);
  KVec3 d = v3(rays[8 * i + 4], rays[8 * i + 5], rays[8 * i + 6]);
  float tmax = rays[8 * i + 3];
  k_bvh_closest(scene, 0, o, d, 0.0f, tmax, K_MASK_PRIMARY, &hits[i]);
  occluded[i] = k_bvh_any(scene, 0, o, d, 0.0f, tmax, K_MASK_SHADOW);
  k_bvh_shadow(scene, 0, o, d, 0.0f, tmax, K_MASK_SHADOW, &transmittance[i]);
}
