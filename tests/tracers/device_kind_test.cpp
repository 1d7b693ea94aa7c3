// Each tracer says whether its rays run on a GPU: the apps' `--convergence auto` depends on it.
#include <gtest/gtest.h>

#include "cohort/tracers/tracer_registry.h"
#include "test_tracers.h"

using namespace cohort;

TEST(TracerDeviceKind, EmbreeAndPoclRenderOnTheCpuCudaOnTheGpu) {
  int checked = 0;
  for (const std::string& kind : test::built_tracers()) {
    if (!test::tracer_runs_here(kind)) continue;
    std::unique_ptr<core::Tracer> tracer = test::make_test_tracer(kind);
    const std::string name = tracer->name();
    if (kind == "embree") EXPECT_FALSE(tracer->renders_on_gpu()) << name;
    if (kind == "cuda") EXPECT_TRUE(tracer->renders_on_gpu()) << name;
    // PoCL's device is the CPU (a "pthread" or "cpu" device); a real GPU's OpenCL driver says GPU.
    if (kind == "opencl" && (name.find("pthread") != std::string::npos || name.find("cpu") != std::string::npos))
      EXPECT_FALSE(tracer->renders_on_gpu()) << name;
    ++checked;
  }
  EXPECT_GE(checked, 1) << "Embree always runs";
}
