// Tracers by name: "embree", "opencl" / "opencl:N" (N-th OpenCL device of all platforms), "cuda" /
// "cuda:N". Compiled into the app (and into tests or benches that want it) so that core never depends
// on the tracer modules.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "cohort/core/tracer.h"

namespace cohort::app {

struct TracerSpec {
  std::string kind;  // embree, opencl, cuda
  int device = 0;
  std::string text;  // as written
};

// Splits "embree,opencl:1"; throws std::invalid_argument naming a malformed entry.
std::vector<TracerSpec> parse_tracer_list(const std::string& list);

// Throws std::runtime_error when this build lacks the tracer or the device cannot be opened.
std::unique_ptr<core::Tracer> make_tracer(const TracerSpec& spec);
std::vector<std::unique_ptr<core::Tracer>> make_tracers(const std::string& list);

// The tracer kinds this binary was built with.
std::vector<std::string> built_tracer_kinds();

}  // namespace cohort::app
