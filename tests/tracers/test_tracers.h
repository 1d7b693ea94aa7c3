// The tracers this build has, for tests that run the same checks on each.
#pragma once

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

namespace cohort::test {

inline std::vector<std::string> built_tracers() {
  std::vector<std::string> names;
#ifdef COHORT_HAVE_EMBREE
  names.push_back("embree");
#endif
#ifdef COHORT_HAVE_OPENCL
  names.push_back("opencl");
#endif
  return names;
}

// Whether this machine can run the tracer at all (an OpenCL build on a machine without any OpenCL
// device skips; a kernel that fails to compile is a failure, not a skip).
inline bool tracer_runs_here(const std::string& name) {
#ifdef COHORT_HAVE_OPENCL
  if (name == "opencl") return !tracers::OpenCLTracer::list_devices().empty();
#endif
  return true;
}

inline std::unique_ptr<core::Tracer> make_test_tracer(const std::string& name) {
#ifdef COHORT_HAVE_EMBREE
  if (name == "embree") return std::make_unique<tracers::EmbreeTracer>();
#endif
#ifdef COHORT_HAVE_OPENCL
  if (name == "opencl") return std::make_unique<tracers::OpenCLTracer>(tracers::OpenCLTracer::Options{});
#endif
  throw std::runtime_error("no tracer named " + name);
}

}  // namespace cohort::test
