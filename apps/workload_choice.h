// `cohort play --target-fps`: whether a session holds a frame rate, and how its WorkloadScaler moves.
//
// Machines without a GPU (the CPU-only Embree fallback) get 30 fps by default: the scaler lowers the
// render scale (down to a quarter of the window) and spp until frames fit, and raises them again when
// there is time to spare. With a GPU, or when the user named --spp or --scale, those stand unless
// --target-fps is given.
#pragma once

#include "cohort/core/workload_scaler.h"

namespace cohort::app {

constexpr int kCpuTargetFps = 30;

// requested: -1 (auto), 0 (off) or a frame rate. workload_given: the user chose spp or scale.
inline int resolve_target_fps(int requested, bool any_gpu_tracer, bool workload_given) {
  if (requested >= 0) return requested;
  return any_gpu_tracer || workload_given ? 0 : kCpuTargetFps;
}

inline core::WorkloadScalerOptions workload_options(int target_fps) {
  core::WorkloadScalerOptions o;
  o.target_ms = 1000.0 / target_fps;
  o.scale_resolution = true;
  o.min_scale = 0.25;
  o.scale_step = 0.05;
  o.min_spp = 1;
  o.max_spp = 16;
  return o;
}

}  // namespace cohort::app
