// The hook through which `cohort bench balance --real` gets real tracers (Embree, OpenCL, CUDA).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "cohort/core/tracer.h"

namespace cohort::app {

// Tracers for the given names ("embree", "opencl", "cuda", "cuda:1", ...), each with its scene already
// applied, ready to render. Throws std::runtime_error saying what is missing when a name cannot be
// served by this build.
std::vector<std::unique_ptr<core::Tracer>> make_real_tracers(const std::vector<std::string>& names);

}  // namespace cohort::app
