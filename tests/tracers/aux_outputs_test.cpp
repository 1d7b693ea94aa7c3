// Auxiliary outputs (kernel/aux_outputs.h): depth, normal, albedo and id of the first opaque hit, and
// motion vectors, checked against the analytic reprojection of known points of a floor, for camera
// motion and for an object's own motion (agreement between tracers: agreement_test.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>

#include "cohort/kernel/rng.h"
#include "test_scenes.h"
#include "test_tracers.h"

using namespace cohort;
using namespace cohort::test;

namespace {

constexpr int kW = 48, kH = 32;
constexpr float kHeight = 100.0f, kTan = 0.5f;

std::shared_ptr<commit::TracerScene> compiled_floor() {
  return std::make_shared<commit::TracerScene>(core::compile_scene(floor_scene(1000.0f, {0.25f, 0.5f, 0.75f})).tracer_scene);
}

// Where a world point appears in a camera's image, in pixels (the camera convention of core/view.h).
glm::vec2 project(const KCamera& c, glm::vec3 p) {
  glm::vec3 d = p - glm::vec3(c.origin[0], c.origin[1], c.origin[2]);
  glm::vec3 f(c.forward[0], c.forward[1], c.forward[2]), r(c.right[0], c.right[1], c.right[2]), u(c.up[0], c.up[1], c.up[2]);
  float z = glm::dot(d, f);
  return {(glm::dot(d, r) / (z * c.tan_half_fov_x) + 1.0f) * 0.5f * float(c.width),
          (1.0f - glm::dot(d, u) / (z * c.tan_half_fov_y)) * 0.5f * float(c.height)};
}

// Checks every pixel's motion against the projection of its floor point (moved by `object_offset`
// back to where it was) into the previous camera.
void expect_floor_motion(const core::GBuffer& g, const KCamera& cam, const KCamera& prev, glm::vec3 object_offset) {
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const size_t p = static_cast<size_t>(y) * kW + x;
      const glm::vec3 point = floor_point(cam, x + 0.5f, y + 0.5f);
      const glm::vec2 was = project(prev, point - object_offset);
      ASSERT_NEAR(g.motion[2 * p], was.x - (x + 0.5f), 2e-3f) << x << "," << y;
      ASSERT_NEAR(g.motion[2 * p + 1], was.y - (y + 0.5f), 2e-3f) << x << "," << y;
    }
}

}  // namespace

TEST(AuxOutputs, FloorGBufferUnderAStillCamera) {
  auto tracer = make_test_tracer("embree");
  const KCamera cam = camera_looking_down({0, 0, kHeight}, kTan, kW, kH);
  const core::GBuffer g = render_aux(*tracer, compiled_floor(), 1, cam, cam);
  for (size_t p = 0; p < g.pixels(); ++p) {
    ASSERT_NEAR(g.depth[p], kHeight, 1e-2f);
    ASSERT_NEAR(g.prev_depth[p], kHeight, 1e-2f);
    ASSERT_NEAR(g.normal[3 * p + 2], 1.0f, 1e-3f);
    ASSERT_NEAR(g.albedo[3 * p + 0], 0.25f, 2e-3f);
    ASSERT_NEAR(g.albedo[3 * p + 1], 0.5f, 2e-3f);
    ASSERT_NEAR(g.albedo[3 * p + 2], 0.75f, 2e-3f);
    ASSERT_EQ(g.id[p], 0u);  // the world
    ASSERT_NEAR(g.motion[2 * p], 0.0f, 1e-3f);
    ASSERT_NEAR(g.motion[2 * p + 1], 0.0f, 1e-3f);
  }
}

TEST(AuxOutputs, CameraTranslationMatchesTheAnalyticReprojection) {
  auto tracer = make_test_tracer("embree");
  const KCamera cam = camera_looking_down({0, 0, kHeight}, kTan, kW, kH);
  const KCamera prev = camera_looking_down({7.0f, -4.0f, kHeight + 10.0f}, kTan, kW, kH);
  const core::GBuffer g = render_aux(*tracer, compiled_floor(), 1, cam, prev);
  expect_floor_motion(g, cam, prev, glm::vec3(0.0f));
  EXPECT_NEAR(g.prev_depth[0], kHeight + 10.0f, 1e-2f);
}

TEST(AuxOutputs, CameraRotationMatchesTheAnalyticReprojection) {
  auto tracer = make_test_tracer("embree");
  const KCamera cam = camera_looking_down({0, 0, kHeight}, kTan, kW, kH);
  KCamera prev = cam;  // rolled 10 degrees about the view axis and tilted 3 degrees
  const float roll = 10.0f * 3.14159265f / 180.0f, tilt = 3.0f * 3.14159265f / 180.0f;
  glm::vec3 right(std::cos(roll), std::sin(roll), 0.0f), up(-std::sin(roll), std::cos(roll), 0.0f);
  glm::vec3 forward(0.0f, 0.0f, -1.0f);
  glm::vec3 f2 = std::cos(tilt) * forward + std::sin(tilt) * up, u2 = std::cos(tilt) * up - std::sin(tilt) * forward;
  for (int k = 0; k < 3; ++k) {
    prev.right[k] = right[k];
    prev.up[k] = u2[k];
    prev.forward[k] = f2[k];
  }
  const core::GBuffer g = render_aux(*tracer, compiled_floor(), 1, cam, prev);
  expect_floor_motion(g, cam, prev, glm::vec3(0.0f));
}

// The floor instance moves by a known offset between two commits: its points were `offset` back, so
// with a still camera each pixel's motion is that offset in pixels.
TEST(AuxOutputs, ObjectMotionFollowsTheInstanceTransform) {
  auto tracer = make_test_tracer("embree");
  const KCamera cam = camera_looking_down({0, 0, kHeight}, kTan, kW, kH);
  auto before = compiled_floor();
  render_aux(*tracer, before, 1, cam, cam);
  auto after = std::make_shared<commit::TracerScene>(*before);
  const glm::vec3 offset(6.0f, -3.0f, 0.0f);
  for (KInstance& inst : after->instances) {
    inst.object_to_world[3] += offset.x;
    inst.object_to_world[7] += offset.y;
    inst.world_to_object[3] -= offset.x;
    inst.world_to_object[7] -= offset.y;
  }
  const core::GBuffer g = render_aux(*tracer, after, 2, cam, cam);
  expect_floor_motion(g, cam, cam, offset);
  EXPECT_NEAR(g.motion[0], -offset.x / (kHeight * kTan) * 0.5f * kW, 1e-3f);
}

// The aux planes travel beside the band (GPU tracers: their own kernel and read, overlapping the band's):
// a band with them has the same colours as one without, and bands of a frame in two parts (the second
// larger, so device buffers grow between them) write exactly the whole frame's planes, on every tracer.
TEST(AuxOutputs, SplitBandsWriteTheWholeFramesPlanesAndTheSameColours) {
  const int w = 40, h = 24, split = 9;
  const KCamera cam = test_room_camera(w, h);
  const KCamera prev = core::make_camera({-180, -130, 125}, {33.0f, 21.0f}, 90.0f, w, h);
  auto room = std::make_shared<commit::TracerScene>(core::compile_scene(test_room()).tracer_scene);
  int checked = 0;
  for (const std::string& kind : built_tracers()) {
    if (!tracer_runs_here(kind)) continue;
    auto tracer = make_test_tracer(kind);
    tracer->apply(commit::CommitBuffer::full(room, 1));
    for (kuint aux_mode : {K_AUX_CENTRE_RAY, K_AUX_PATH_FIRST_HIT}) {
    SCOPED_TRACE(aux_mode == K_AUX_CENTRE_RAY ? "centre rays" : "the paths' first hits");
    auto render = [&](core::BandBuffer& band, bool aux, int begin, int end) {
      core::BandJob job;
      job.params = frame_params(K_MODE_PATH, 1, 1, h);
      job.params.row_begin = kuint(begin);
      job.params.row_end = kuint(end);
      job.params.aux_outputs = aux ? aux_mode : 0u;
      job.camera = cam;
      job.previous_camera = prev;
      tracer->render_band(job, band);
    };
    for (core::BandFormat format : {core::BandFormat::rgb16f, core::BandFormat::rgb9e5, core::BandFormat::rgba32f}) {
      core::BandBuffer whole(w, h, format), parts(w, h, format), plain(w, h, format);
      whole.enable_aux(true);
      parts.enable_aux(true);
      render(whole, true, 0, h);
      render(parts, true, 0, split);
      render(parts, true, split, h);
      render(plain, false, 0, h);
      ASSERT_EQ(std::memcmp(whole.data(), plain.data(), whole.bytes()), 0) << kind << ": the aux planes changed the colours";
      ASSERT_EQ(std::memcmp(whole.data(), parts.data(), whole.bytes()), 0) << kind << ": split bands' colours differ";
      ASSERT_EQ(std::memcmp(whole.aux_data(), parts.aux_data(), whole.aux_bytes()), 0) << kind << ": split bands' planes differ";
      const core::GBuffer g = [&] {
        core::GBuffer out;
        out.resize(w, h);
        whole.copy_aux_rows_to(out, 0, h);
        return out;
      }();
      size_t hits = 0;
      for (size_t p = 0; p < g.pixels(); ++p) hits += g.depth[p] > 0.0f ? 1u : 0u;
      EXPECT_GT(hits, g.pixels() / 2) << kind << ": the planes are mostly empty";
    }
    }
    ++checked;
  }
  EXPECT_GT(checked, 0);
}

// K_AUX_PATH_FIRST_HIT: the planes of each pixel are those of its first sample's jittered camera ray, and
// its motion is measured from that sample's position, on every tracer: a floor under a moving camera.
TEST(AuxOutputs, FirstHitPlanesFollowTheJitteredSampleOnEveryTracer) {
  const KCamera cam = camera_looking_down({0, 0, kHeight}, kTan, kW, kH);
  const KCamera prev = camera_looking_down({7.0f, -4.0f, kHeight + 10.0f}, kTan, kW, kH);
  const kuint frame_index = frame_params(K_MODE_PATH, 1, 1, kH).frame_index;
  int checked = 0, off_centre = 0;
  for (const std::string& kind : built_tracers()) {
    if (!tracer_runs_here(kind)) continue;
    SCOPED_TRACE(kind);
    auto tracer = make_test_tracer(kind);
    const core::GBuffer g = render_aux(*tracer, compiled_floor(), 1, cam, prev, K_AUX_PATH_FIRST_HIT);
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) {
        KRng rng = k_rng_seed(kuint(x), kuint(y), frame_index, 0u);
        const float sx = float(x) + k_rng_next(&rng), sy = float(y) + k_rng_next(&rng);
        off_centre += std::fabs(sx - (float(x) + 0.5f)) > 0.1f ? 1 : 0;
        const size_t p = static_cast<size_t>(y) * kW + x;
        const glm::vec3 point = floor_point(cam, sx, sy);
        const glm::vec2 was = project(prev, point);
        ASSERT_NEAR(g.motion[2 * p], was.x - sx, 2e-3f) << x << "," << y;
        ASSERT_NEAR(g.motion[2 * p + 1], was.y - sy, 2e-3f) << x << "," << y;
        ASSERT_NEAR(g.depth[p], kHeight, 1e-2f);
        ASSERT_NEAR(g.prev_depth[p], kHeight + 10.0f, 1e-2f);
        ASSERT_NEAR(g.normal[3 * p + 2], 1.0f, 1e-3f);
        ASSERT_NEAR(g.albedo[3 * p + 1], 0.5f, 2e-3f);
        ASSERT_EQ(g.id[p], 0u);
      }
    ++checked;
  }
  EXPECT_GT(checked, 0);
  EXPECT_GT(off_centre, kW * kH / 2) << "the samples should be jittered off the pixels' centres";
}
