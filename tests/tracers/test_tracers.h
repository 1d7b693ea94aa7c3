// The tracers this build has, for tests that run the same checks on each. COHORT_TEST_OPENCL_DEVICE
// picks the OpenCL device (index into OpenCLTracer::list_devices(); default 0).
#pragma once

#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "cohort/core/tracer.h"
#ifdef COHORT_HAVE_EMBREE
#include "cohort/tracers/embree_tracer.h"
#endif
#ifdef COHORT_HAVE_OPENCL
#include "cohort/tracers/opencl_tracer.h"
#endif
#ifdef COHORT_HAVE_CUDA
#include "cohort/tracers/cuda_tracer.h"
#endif

namespace cohort::test {

inline std::vector<std::string> built_tracers() {
  std::vector<std::string> names;
#ifdef COHORT_HAVE_EMBREE
  names.push_back("embree");
#endif
#ifdef COHORT_HAVE_OPENCL
  names.push_back("opencl");
#endif
#ifdef COHORT_HAVE_CUDA
  names.push_back("cuda");
#endif
  return names;
}

// Whether this machine can run the tracer at all (an OpenCL build on a machine without any OpenCL
// device skips; a kernel that fails to compile is a failure, not a skip).
inline bool tracer_runs_here(const std::string& name) {
#ifdef COHORT_HAVE_OPENCL
  if (name == "opencl") return !tracers::OpenCLTracer::list_devices().empty();
#endif
#ifdef COHORT_HAVE_CUDA
  if (name == "cuda") return tracers::cuda_device_count() > 0;
#endif
  return true;
}

inline std::unique_ptr<core::Tracer> make_test_tracer(const std::string& name) {
#ifdef COHORT_HAVE_EMBREE
  if (name == "embree") return std::make_unique<tracers::EmbreeTracer>();
#endif
#ifdef COHORT_HAVE_OPENCL
  if (name == "opencl") {
    tracers::OpenCLTracer::Options options;
    if (const char* device = std::getenv("COHORT_TEST_OPENCL_DEVICE")) options.device = std::atoi(device);
    return std::make_unique<tracers::OpenCLTracer>(options);
  }
#endif
#ifdef COHORT_HAVE_CUDA
  if (name == "cuda") return std::make_unique<tracers::CudaTracer>(0);
  if (name.rfind("cuda:", 0) == 0) return std::make_unique<tracers::CudaTracer>(std::stoi(name.substr(5)));
#endif
  throw std::runtime_error("no tracer named " + name);
}

}  // namespace cohort::test
