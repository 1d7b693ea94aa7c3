// Rendering helpers for the tracer tests: a camera, frame parameters, one band rendered, pixel reads
// and previews. The scenes they render are the shared in-memory ones of cohort_test_support.
#pragma once

#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <gtest/gtest.h>

#include "cohort/commit/commit_buffer.h"
#include "cohort/core/band_buffer.h"
#include "cohort/core/frame_buffer.h"
#include "cohort/core/gbuffer.h"
#include "cohort/core/gpu_scene.h"
#include "cohort/core/image_output.h"
#include "cohort/core/tracer.h"
#include "cohort/core/frame_defaults.h"
#include "cohort/core/view.h"
#include "cohort/scene/map_loader.h"
#include "cohort/scene/scene.h"
#include "cohort/scene/vfs.h"
#include "cohort/test_support/scene_builders.h"
#include "cohort/test_support/test_scenes.h"
#include "test_tracers.h"

namespace cohort::test {

// A pinhole camera at `origin` looking down -Z; image right is +X, image up is +Y.
inline KCamera camera_looking_down(glm::vec3 origin, float tan_half_fov, int width, int height) {
  KCamera c{};
  c.origin[0] = origin.x; c.origin[1] = origin.y; c.origin[2] = origin.z;
  c.forward[2] = -1.0f;
  c.right[0] = 1.0f;
  c.up[1] = 1.0f;
  c.width = static_cast<uint32_t>(width);
  c.height = static_cast<uint32_t>(height);
  c.tan_half_fov_x = tan_half_fov;
  c.tan_half_fov_y = tan_half_fov * float(height) / float(width);
  return c;
}

// A pinhole camera at `origin` looking at `target`, image up toward +Z.
inline KCamera camera_looking_at(glm::vec3 origin, glm::vec3 target, float tan_half_fov, int width, int height) {
  KCamera c{};
  const glm::vec3 forward = glm::normalize(target - origin);
  const glm::vec3 right = glm::normalize(glm::cross(forward, glm::vec3(0, 0, 1)));
  const glm::vec3 up = glm::cross(right, forward);
  for (int i = 0; i < 3; ++i) {
    c.origin[i] = origin[i];
    c.forward[i] = forward[i];
    c.right[i] = right[i];
    c.up[i] = up[i];
  }
  c.width = static_cast<uint32_t>(width);
  c.height = static_cast<uint32_t>(height);
  c.tan_half_fov_x = tan_half_fov;
  c.tan_half_fov_y = tan_half_fov * float(height) / float(width);
  return c;
}

inline KFrameParams frame_params(uint32_t mode, uint32_t spp, uint32_t max_bounces, int height) {
  KFrameParams p = core::default_frame_params();
  p.spp = spp;
  p.max_bounces = max_bounces;
  p.mode = mode;
  p.row_begin = 0;
  p.row_end = static_cast<uint32_t>(height);
  // Checked against analytic values and pixel by pixel between builds and devices: no firefly clamp,
  // hard shadows, no Russian roulette on paths or on shadow rays (a roulette turns last-bit differences
  // into flipped samples; LightSampling.ShadowRayRouletteKeepsTheImageUnbiased tests it on its own).
  p.firefly_clamp = 0.0f;
  p.soft_shadow_scale = 0.0f;
  p.rr_start = 100.0f;
  p.shadow_rr = 0.0f;
  return p;
}

// The settings the tracers' agreement tests (agreement_test.cpp, cuda_test.cpp) compare images at: 16 spp
// with the firefly clamp, soft shadows and Russian roulette from bounce 2 on, at one frame index.
inline KFrameParams agreement_params(uint32_t mode, uint32_t bounces, int height) {
  KFrameParams p = frame_params(mode, 16, bounces, height);
  p.firefly_clamp = 10.0f;
  p.soft_shadow_scale = 1.0f;
  p.rr_start = 2.0f;
  p.frame_index = 7;
  return p;
}

// One whole-frame band from the scene the tracer holds now.
inline core::FrameBuffer render_frame(core::Tracer& tracer, const KCamera& camera, const KFrameParams& params) {
  core::FrameBuffer fb;
  fb.resize(static_cast<int>(camera.width), static_cast<int>(camera.height));
  core::BandJob job;
  job.params = params;
  job.camera = camera;
  tracer.render_band(job, fb);
  return fb;
}

// The scene compiled and applied as a full resync, then one whole-frame band of it.
inline core::FrameBuffer render(core::Tracer& tracer, const scene::Scene& scene, const KCamera& camera,
                                const KFrameParams& params) {
  auto compiled = std::make_shared<commit::TracerScene>(core::compile_scene(scene).tracer_scene);
  tracer.apply(commit::CommitBuffer::full(compiled, 1));
  return render_frame(tracer, camera, params);
}

// The test map on disk (assets/testmap, made by tools/gen_testmap.py), loaded as `cohort` loads a map.
inline scene::Scene load_test_map() {
  scene::Vfs vfs;
  return scene::load_map(vfs, std::string(COHORT_SOURCE_DIR) + "/assets/testmap/maps/testmap.map");
}

// The test map agreements' settings (8 spp, 1 bounce, a shadow ray per light, soft shadows, a firefly
// clamp and path roulette from the second bounce), at which Embree and the other tracers are compared.
inline KFrameParams testmap_agreement_params(int height) {
  KFrameParams params = frame_params(K_MODE_PATH, 8, 1, height);
  params.light_samples = 0;
  params.firefly_clamp = 5.0f;
  params.soft_shadow_scale = 0.2f;
  params.rr_start = 2.0f;
  return params;
}

// The auxiliary planes (kernel/aux_outputs.h) of one whole-frame band from the tracer's current scene.
// aux_mode: K_AUX_CENTRE_RAY or K_AUX_PATH_FIRST_HIT (kernel/layout.h).
// Pixel p of two tracers' aux planes (same surface id) agree within the tracer agreement tolerance: depth
// relative, motion, normal and albedo absolute.
inline ::testing::AssertionResult aux_planes_agree(const core::GBuffer& a, const core::GBuffer& b, size_t p) {
  auto near = [](float u, float v, float tolerance) { return std::fabs(u - v) <= tolerance; };
  if (!near(a.depth[p], b.depth[p], 1e-2f * std::max(1.0f, a.depth[p])))
    return ::testing::AssertionFailure() << "depth " << a.depth[p] << " against " << b.depth[p];
  for (int k = 0; k < 2; ++k)
    if (!near(a.motion[2 * p + k], b.motion[2 * p + k], 1e-2f))
      return ::testing::AssertionFailure() << "motion[" << k << "] " << a.motion[2 * p + k] << " against "
                                           << b.motion[2 * p + k];
  for (int k = 0; k < 3; ++k) {
    if (!near(a.normal[3 * p + k], b.normal[3 * p + k], 1e-2f))
      return ::testing::AssertionFailure() << "normal[" << k << "] " << a.normal[3 * p + k] << " against "
                                           << b.normal[3 * p + k];
    if (!near(a.albedo[3 * p + k], b.albedo[3 * p + k], 1e-2f))
      return ::testing::AssertionFailure() << "albedo[" << k << "] " << a.albedo[3 * p + k] << " against "
                                           << b.albedo[3 * p + k];
  }
  return ::testing::AssertionSuccess();
}

inline core::GBuffer render_aux_band(core::Tracer& tracer, const KCamera& camera, const KCamera& previous,
                                     kuint aux_mode = K_AUX_CENTRE_RAY) {
  core::BandBuffer band(static_cast<int>(camera.width), static_cast<int>(camera.height), core::BandFormat::rgba32f);
  band.enable_aux(true);
  core::BandJob job;
  job.params = frame_params(K_MODE_PATH, 1, 1, static_cast<int>(camera.height));
  job.params.aux_outputs = aux_mode;
  job.camera = camera;
  job.previous_camera = previous;
  tracer.render_band(job, band);
  core::GBuffer g;
  g.resize(band.width(), band.height());
  band.copy_aux_rows_to(g, 0, band.height());
  return g;
}

// The same after a full commit of `scene` at `frame`.
inline core::GBuffer render_aux(core::Tracer& tracer, const std::shared_ptr<commit::TracerScene>& scene, uint64_t frame,
                                const KCamera& camera, const KCamera& previous, kuint aux_mode = K_AUX_CENTRE_RAY) {
  tracer.apply(commit::CommitBuffer::full(scene, frame));
  return render_aux_band(tracer, camera, previous, aux_mode);
}

// Where the ray through image point (px, py) of a camera_looking_down meets z = 0.
inline glm::vec3 floor_point(const KCamera& c, float px, float py) {
  float sx = (2.0f * px / float(c.width) - 1.0f) * c.tan_half_fov_x;
  float sy = (1.0f - 2.0f * py / float(c.height)) * c.tan_half_fov_y;
  float h = c.origin[2];
  return {c.origin[0] + sx * h, c.origin[1] + sy * h, 0.0f};
}

inline glm::vec3 pixel(const core::FrameBuffer& fb, int x, int y) {
  const float* p = fb.row(y) + 4 * x;
  return {p[0], p[1], p[2]};
}

// RMSE over the RGB channels of two frames of one size; *mean gets the mean of both frames' channels
// (the scale the agreement tests hold the error against).
inline double rgb_rmse(const core::FrameBuffer& a, const core::FrameBuffer& b, double* mean) {
  double sum = 0.0, sum_sq = 0.0;
  size_t n = 0;
  for (size_t i = 0; i < a.rgba.size(); ++i) {
    if (i % 4 == 3) continue;
    const double d = double(a.rgba[i]) - double(b.rgba[i]);
    sum_sq += d * d;
    sum += 0.5 * (double(a.rgba[i]) + double(b.rgba[i]));
    ++n;
  }
  *mean = sum / double(n);
  return std::sqrt(sum_sq / double(n));
}

// The small rooms' Embree-against-OpenCL check (16 spp, 3 bounces, soft shadows, a firefly clamp): every
// value finite, a mean above 0.05, and an RMSE under 0.5% of it. `label` names the room in the output.
inline void expect_embree_and_opencl_agree(const scene::Scene& scene, const KCamera& camera, const std::string& label) {
  KFrameParams params = frame_params(K_MODE_PATH, 16, 3, static_cast<int>(camera.height));
  params.firefly_clamp = 10.0f;
  params.soft_shadow_scale = 1.0f;
  params.frame_index = 5;
  auto embree = make_test_tracer("embree");
  auto opencl = make_test_tracer("opencl");
  const core::FrameBuffer a = render(*embree, scene, camera, params);
  const core::FrameBuffer b = render(*opencl, scene, camera, params);
  for (size_t i = 0; i < a.rgba.size(); ++i) ASSERT_TRUE(std::isfinite(a.rgba[i]) && std::isfinite(b.rgba[i])) << i;
  double mean = 0.0;
  const double error = rgb_rmse(a, b, &mean);
  std::cout << label << ": RMSE embree/opencl " << error << ", mean " << mean << "\n";
  EXPECT_GT(mean, 0.05);
  EXPECT_LT(error, 0.005 * mean);
}

inline double mean_luminance(const core::FrameBuffer& fb) {
  double sum = 0.0;
  for (int y = 0; y < fb.height; ++y)
    for (int x = 0; x < fb.width; ++x) {
      glm::vec3 c = pixel(fb, x, y);
      sum += 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
    }
  return sum / (double(fb.width) * fb.height);
}

// A camera inside test_room looking across it.
inline KCamera test_room_camera(int width, int height) {
  return core::make_camera({-190, -130, 120}, {35.0f, 20.0f}, 90.0f, width, height);  // 20 degrees down
}

// Writes an 8-bit preview (clamped, gamma 2.2) for looking at test images (COHORT_TEST_IMAGES=dir).
// Writes a PNG, or a PPM beside it in builds without an image library (the GPU machine's).
inline void write_preview(const std::string& requested, const core::FrameBuffer& fb) {
  std::string file = requested;
  if (!core::have_image_library() && file.size() > 4 && file.substr(file.size() - 4) == ".png")
    file = file.substr(0, file.size() - 4) + ".ppm";
  std::vector<uint8_t> rgba(size_t(fb.width) * fb.height * 4);
  for (size_t i = 0; i < rgba.size(); ++i) {
    float v = i % 4 == 3 ? 1.0f : std::pow(std::clamp(fb.rgba[i], 0.0f, 1.0f), 1.0f / 2.2f);
    rgba[i] = static_cast<uint8_t>(v * 255.0f + 0.5f);
  }
  core::write_ldr_image(file, fb.width, fb.height, rgba);
}

}  // namespace cohort::test
