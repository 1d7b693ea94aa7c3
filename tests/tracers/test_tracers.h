// The tracers this build has, for tests that run the same checks on each, made by the tracer registry.
// COHORT_TEST_OPENCL_DEVICE picks the device a plain "opencl" names (index into
// OpenCLTracer::list_devices(); default 0).
#pragma once

#include <cstdlib>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cohort/tracers/tracer_registry.h"

namespace cohort::test {

inline std::vector<std::string> built_tracers() { return tracers::built_tracer_kinds(); }

// Whether this machine can run the tracer at all (an OpenCL build on a machine without any OpenCL
// device skips; a kernel that fails to compile is a failure, not a skip).
inline bool tracer_runs_here(const std::string& kind) { return tracers::device_count(kind) > 0; }

// The OpenCL device a plain "opencl" names in the tests: COHORT_TEST_OPENCL_DEVICE, else 0 (the
// registry's and OpenCLTracer::Options' default).
inline int test_opencl_device() {
  const char* device = std::getenv("COHORT_TEST_OPENCL_DEVICE");
  return device ? std::atoi(device) : 0;
}

// name: a kind or "kind:N", as the registry takes it.
inline std::unique_ptr<core::Tracer> make_test_tracer(const std::string& name) {
  tracers::TracerSpec spec = tracers::parse_tracer_list(name).front();
  if (name == "opencl") spec.device = test_opencl_device();
  return tracers::make_tracer(spec);
}

// A fixture for the checks run on each built tracer (INSTANTIATE_TEST_SUITE_P over built_tracers()): the
// parameter is the tracer's kind; tracer_ is one made for the test, which skips where the kind cannot run.
class EachTracer : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    if (!tracer_runs_here(GetParam())) GTEST_SKIP() << GetParam() << ": no device on this machine";
    tracer_ = make_test_tracer(GetParam());
  }
  std::unique_ptr<core::Tracer> tracer_;
};

// The message the registry gives when `variable` holds `value` while it makes `name`'s tracer ("" if none:
// it made the tracer); the variable is unset afterwards.
inline std::string registry_error_with(const char* variable, const char* value, const std::string& name) {
  ::setenv(variable, value, 1);
  std::string message;
  try {
    tracers::make_tracer(tracers::parse_tracer_list(name).front());
  } catch (const std::invalid_argument& e) {
    message = e.what();
  }
  ::unsetenv(variable);
  return message;
}

}  // namespace cohort::test
