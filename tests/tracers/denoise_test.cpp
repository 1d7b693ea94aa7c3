// Open Image Denoise on real renders: a 1-spp frame of the generated test map, denoised, is much closer
// to a converged render of the same view than the raw frame, with or without guide images (albedo and
// normals rendered by the same tracer). Skips only when the library is absent (tools/fetch_oidn.sh
// installs it; tools/setup.sh runs that).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <iostream>
#include <string>

#include "cohort/core/oidn_denoiser.h"
#include "cohort/core/view.h"
#include "cohort/scene/map_loader.h"
#include "test_scenes.h"
#include "test_tracers.h"

using namespace cohort;
using namespace cohort::test;

namespace {

// RMSE after a Reinhard curve, so the error is measured as a viewer sees it rather than dominated by the
// few pixels that look straight into a light.
double rmse_display(const core::FrameBuffer& a, const core::FrameBuffer& b) {
  auto display = [](float v) { return double(v) / (1.0 + double(v)); };
  double sum_sq = 0.0;
  size_t n = 0;
  for (size_t i = 0; i < a.rgba.size(); ++i) {
    if (i % 4 == 3) continue;
    double d = display(a.rgba[i]) - display(b.rgba[i]);
    sum_sq += d * d;
    ++n;
  }
  return std::sqrt(sum_sq / double(n));
}

// A frame's RGB as a guide plane (3 floats a pixel, GBuffer's layout).
std::vector<float> rgb_plane(const core::FrameBuffer& f) {
  std::vector<float> rgb;
  for (size_t i = 0; i < f.rgba.size(); ++i)
    if (i % 4 != 3) rgb.push_back(f.rgba[i]);
  return rgb;
}

bool all_finite(const core::FrameBuffer& f) {
  for (float v : f.rgba)
    if (!std::isfinite(v)) return false;
  return true;
}

class OidnOnTestMap : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string where;
    if (!core::OidnDenoiser::library_available(&where)) GTEST_SKIP() << where;
    if (!tracer_runs_here("embree")) GTEST_SKIP() << "needs the Embree tracer";
    map_ = load_test_map();
    camera_ = core::make_camera(core::player_eye(map_), {map_.player_yaw, 0.0f}, core::kDefaultFovX, kWidth, kHeight);
    tracer_ = make_test_tracer("embree");
  }

  core::FrameBuffer render_mode(uint32_t mode, uint32_t spp, uint32_t frame) {
    KFrameParams params = frame_params(mode, spp, 1, kHeight);
    params.light_samples = 1;
    params.firefly_clamp = 5.0f;
    params.frame_index = frame;
    return render(*tracer_, map_, camera_, params);
  }

  static constexpr int kWidth = 160, kHeight = 90;
  scene::Scene map_;
  KCamera camera_{};
  std::unique_ptr<core::Tracer> tracer_;
};

}  // namespace

TEST(OidnDenoiser, UnknownDeviceNameIsRejected) {
  EXPECT_THROW(core::parse_oidn_device("gpu"), std::invalid_argument);
  EXPECT_EQ(core::parse_oidn_device("cuda"), core::OidnDevice::kCuda);
  EXPECT_THROW(core::parse_oidn_quality("best"), std::invalid_argument);
  EXPECT_EQ(core::parse_oidn_quality("fast"), core::OidnQuality::kFast);
}

TEST_F(OidnOnTestMap, DenoisedFrameIsCloserToTheConvergedOne) {
  const core::FrameBuffer reference = render_mode(K_MODE_PATH, 256, 7);
  const core::FrameBuffer noisy = render_mode(K_MODE_PATH, 1, 1);
  auto denoiser = core::OidnDenoiser::open(core::OidnDevice::kCpu);

  core::FrameBuffer plain;
  denoiser->denoise(noisy, plain);
  const std::vector<float> albedo = rgb_plane(render_mode(K_MODE_ALBEDO, 1, 1));
  // The normals view encodes n * 0.5 + 0.5; the denoiser takes normals in [-1, 1].
  std::vector<float> normal = rgb_plane(render_mode(K_MODE_NORMALS, 1, 1));
  for (float& v : normal) v = 2.0f * v - 1.0f;
  core::FrameBuffer guided;
  denoiser->denoise(noisy, guided, {&albedo, &normal});

  core::FrameBuffer quick;
  core::OidnDenoiser::open(core::OidnDevice::kCpu, core::OidnQuality::kFast)->denoise(noisy, quick);

  const double raw_error = rmse_display(noisy, reference);
  const double quick_error = rmse_display(quick, reference);
  const double plain_error = rmse_display(plain, reference);
  const double guided_error = rmse_display(guided, reference);
  std::cout << "display RMSE against 256 spp: 1 spp " << raw_error << ", denoised " << plain_error << ", with guides "
            << guided_error << ", fast quality " << quick_error << " (" << denoiser->library_path() << ")\n";
  ASSERT_TRUE(all_finite(plain));
  ASSERT_TRUE(all_finite(guided));
  ASSERT_TRUE(all_finite(quick));
  EXPECT_LT(quick_error, 0.7 * raw_error);
  EXPECT_LT(plain_error, 0.6 * raw_error);  // measured: about 0.48
  EXPECT_LT(guided_error, 0.6 * raw_error);  // measured: about 0.51 (guides keep texture detail)
  EXPECT_EQ(plain.width, noisy.width);
  EXPECT_EQ(plain.rgba[3], noisy.rgba[3]);
}

TEST_F(OidnOnTestMap, DenoisesInPlaceAndAfterAResize) {
  auto denoiser = core::OidnDenoiser::open(core::OidnDevice::kCpu);
  core::FrameBuffer frame = render_mode(K_MODE_PATH, 1, 3);
  const core::FrameBuffer copy = frame;
  core::FrameBuffer separate;
  denoiser->denoise(copy, separate);
  denoiser->denoise(frame, frame);
  EXPECT_EQ(frame.rgba, separate.rgba);

  core::FrameBuffer small;
  small.resize(32, 16);
  for (size_t i = 0; i < small.rgba.size(); ++i) small.rgba[i] = (i % 7) * 0.1f;
  core::FrameBuffer out;
  denoiser->denoise(small, out);
  EXPECT_EQ(out.width, 32);
  EXPECT_EQ(out.height, 16);
  EXPECT_TRUE(all_finite(out));
}

// On an NVIDIA GPU (OIDN's CUDA device; skipped where it cannot open): the same filter, its images moved by
// DMA to the device and back, denoises as the CPU device does.
TEST_F(OidnOnTestMap, CudaDeviceDenoisesAsTheCpuDeviceDoes) {
  std::unique_ptr<core::OidnDenoiser> gpu;
  try {
    gpu = core::OidnDenoiser::open(core::OidnDevice::kCuda);
  } catch (const std::exception& e) {
    GTEST_SKIP() << e.what();
  }
  const core::FrameBuffer reference = render_mode(K_MODE_PATH, 256, 7);
  const core::FrameBuffer noisy = render_mode(K_MODE_PATH, 1, 1);
  const std::vector<float> albedo = rgb_plane(render_mode(K_MODE_ALBEDO, 1, 1));
  std::vector<float> normal = rgb_plane(render_mode(K_MODE_NORMALS, 1, 1));
  for (float& v : normal) v = 2.0f * v - 1.0f;
  core::FrameBuffer on_gpu, on_cpu;
  gpu->denoise(noisy, on_gpu, {&albedo, &normal});
  core::OidnDenoiser::open(core::OidnDevice::kCpu)->denoise(noisy, on_cpu, {&albedo, &normal});
  ASSERT_TRUE(all_finite(on_gpu));
  const double raw_error = rmse_display(noisy, reference);
  const double gpu_error = rmse_display(on_gpu, reference);
  const double apart = rmse_display(on_gpu, on_cpu);
  std::cout << "display RMSE against 256 spp: 1 spp " << raw_error << ", CUDA device " << gpu_error
            << "; CUDA against CPU " << apart << "\n";
  EXPECT_LT(gpu_error, 0.6 * raw_error);
  EXPECT_LT(apart, 0.2 * raw_error);
}
