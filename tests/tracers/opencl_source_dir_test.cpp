// COHORT_OPENCL_SOURCE_DIR: the OpenCL tracer builds its two programs from a folder's plain OpenCL C
// (<build>/opencl_source holds the built-in programs in that form) instead of the source built into it.
// The folder's programs draw the built-in image bit for bit; a folder that lacks a program, or a program that
// does not compile, stops the tracer with the path or the build log, never a tracer built from something else.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>

#include "band_frames.h"
#include "test_scenes.h"
#include "test_tracers.h"

#ifdef COHORT_HAVE_OPENCL
#include "cohort/tracers/opencl_tracer.h"
#endif

using namespace cohort;
using namespace cohort::test;

#ifdef COHORT_HAVE_OPENCL
namespace {

class SourceDirForScope {
 public:
  explicit SourceDirForScope(const std::filesystem::path& dir) { ::setenv("COHORT_OPENCL_SOURCE_DIR", dir.c_str(), 1); }
  ~SourceDirForScope() { ::unsetenv("COHORT_OPENCL_SOURCE_DIR"); }
  SourceDirForScope(const SourceDirForScope&) = delete;
  SourceDirForScope& operator=(const SourceDirForScope&) = delete;
};

// A wavefront tracer, so both programs (the shading one and the walks) are built.
std::unique_ptr<tracers::OpenCLTracer> wavefront_tracer() {
  tracers::OpenCLTracer::Options options;
  options.device = test_opencl_device();
  options.wavefront = tracers::OpenCLTracer::Options::Wavefront::always;
  return std::make_unique<tracers::OpenCLTracer>(options);
}

std::filesystem::path fresh_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("cohort_opencl_source_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

std::string message_of_construction() {
  try {
    wavefront_tracer();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(OpenCLSourceDir, TheBuiltInProgramsWrittenOutDrawTheBuiltInImage) {
  const View view = room_view(32, 16);
  const KFrameParams params = frame_params(K_MODE_PATH, 1, 2, 16);
  BandFrame built_in = render_in_bands(*wavefront_tracer(), view, params, {0, 8, 16});
  const std::filesystem::path plain = std::filesystem::path(COHORT_BINARY_DIR) / "opencl_source";
  if (!std::filesystem::exists(plain / "render_band.cl"))
    GTEST_SKIP() << plain << " is not here (the test binary runs away from its build tree)";
  SourceDirForScope scope(plain);
  BandFrame from_dir = render_in_bands(*wavefront_tracer(), view, params, {0, 8, 16});
  expect_same_band_frame(built_in.frame, built_in.row_work, from_dir.frame, from_dir.row_work, false, 16,
                         "the built-in programs'");
}

TEST(OpenCLSourceDir, AFolderWithoutTheProgramsNamesThePathItMissed) {
  const auto dir = fresh_dir("empty");
  SourceDirForScope scope(dir);
  const std::string message = message_of_construction();
  EXPECT_NE(message.find((dir / "render_band.cl").string()), std::string::npos) << message;
  EXPECT_NE(message.find("cannot be read"), std::string::npos) << message;
}

TEST(OpenCLSourceDir, AProgramThatDoesNotCompileStopsTheTracerWithItsBuildLog) {
  const auto dir = fresh_dir("broken");
  std::ofstream(dir / "render_band.cl") << "__kernel void cohort_render_band(__global float* out {\n";
  SourceDirForScope scope(dir);
  const std::string message = message_of_construction();
  EXPECT_NE(message.find("kernel build failed"), std::string::npos) << message;
}

#endif
