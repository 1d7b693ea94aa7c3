#include "real_tracers.h"

#include <stdexcept>

namespace cohort::app {

// The tracer modules register their factories here once they exist (issues 8-10); until then every
// name is refused with the reason, and `cohort bench balance` falls back to simulated tracers only.
std::vector<std::unique_ptr<core::Tracer>> make_real_tracers(const std::vector<std::string>& names) {
  std::string list;
  for (const std::string& n : names) list += (list.empty() ? "" : ",") + n;
  throw std::runtime_error("no real tracers are built into this binary yet (asked for: " + list +
                           "); the Embree/OpenCL/CUDA tracers register in apps/real_tracers.cpp");
}

}  // namespace cohort::app
