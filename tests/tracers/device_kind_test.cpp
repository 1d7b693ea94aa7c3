// Each tracer says whether its rays run on a GPU: the apps' `--convergence auto` depends on it.
#include <gtest/gtest.h>

#include "cohort/tracers/device_listing.h"
#include "cohort/tracers/tracer_registry.h"
#include "test_tracers.h"

using namespace cohort;

TEST(TracerDeviceKind, EmbreeAndPoclRenderOnTheCpuCudaOnTheGpu) {
  int checked = 0;
  for (const std::string& kind : test::built_tracers()) {
    if (!test::tracer_runs_here(kind)) continue;
    std::unique_ptr<core::Tracer> tracer = test::make_test_tracer(kind);
    const std::string name = tracer->name();
    if (kind == "embree") { EXPECT_FALSE(tracer->renders_on_gpu()) << name; }
    if (kind == "cuda") { EXPECT_TRUE(tracer->renders_on_gpu()) << name; }
    // PoCL's device is the CPU (a "pthread" or "cpu" device); a real GPU's OpenCL driver says GPU.
    if (kind == "opencl" && (name.find("pthread") != std::string::npos || name.find("cpu") != std::string::npos)) {
      EXPECT_FALSE(tracer->renders_on_gpu()) << name;
    }
    ++checked;
  }
  EXPECT_GE(checked, 1) << "Embree always runs";
}

// `cohort devices` says GPU exactly for the devices whose tracer says it renders on a GPU.
TEST(TracerDeviceKind, TheListingAgreesWithTheTracers) {
  int checked = 0;
  for (const tracers::TracerDevice& d : tracers::list_tracer_devices()) {
    if (d.tracer.rfind("opencl:", 0) != 0 && d.tracer.rfind("cuda:", 0) != 0) continue;
    std::unique_ptr<core::Tracer> tracer = tracers::make_tracer(tracers::parse_tracer_list(d.tracer).front());
    EXPECT_EQ(tracer->renders_on_gpu(), d.kind == tracers::DeviceKind::gpu) << d.tracer << " " << tracer->name();
    ++checked;
  }
  if (checked == 0) GTEST_SKIP() << "no OpenCL or CUDA device here";
}
