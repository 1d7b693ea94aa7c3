#pragma once

#include <stdexcept>
#include <string>

#include <cuda_runtime.h>

namespace cohort::tracers {

// CUDA errors become exceptions naming the call, so the frame loop can drop this tracer for the frame.
inline void cuda_check(cudaError_t err, const char* what, const char* file, int line) {
  if (err != cudaSuccess)
    throw std::runtime_error(std::string("CUDA: ") + what + " failed at " + file + ":" + std::to_string(line) + ": " +
                             cudaGetErrorString(err));
}

}  // namespace cohort::tracers

#define COHORT_CUDA(call) ::cohort::tracers::cuda_check((call), #call, __FILE__, __LINE__)
