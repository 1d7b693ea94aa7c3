// Tracers produce the same image for the same input (Brigade §4.1.4): the Embree and OpenCL tracers
// run the same integrator with the same per-pixel random numbers, so their images differ only where
// floating-point differences send a path another way. Bound: RMSE below 0.5% of the mean pixel value
// per channel, at 16 spp (noise between two 16-spp renders with different frame indices is far above
// it, so the bound would catch a tracer drawing different samples or shading differently).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>

#include <filesystem>

#include "cohort/core/scene_pack.h"
#include "cohort/core/view.h"
#include "cohort/scene/map_loader.h"
#include "test_scenes.h"
#include "test_tracers.h"

using namespace cohort;
using namespace cohort::test;

namespace {

struct Case {
  uint32_t mode;
  uint32_t bounces;
  const char* name;
  uint32_t light_samples = 1;
  uint32_t light_sampling = K_LIGHTS_TREE;
  uint32_t emissive_samples = 1;
};

// The band format tests' band: the test room at 48x32, paths of one bounce at 2 spp, rows 8 to the end (a
// band that does not start at row 0: the RGB9E5 dither counts pixels from the frame's first).
constexpr int kBandWidth = 48, kBandHeight = 32, kBandFirstRow = 8;
core::BandJob room_band_job() {
  core::BandJob job;
  job.params = frame_params(K_MODE_PATH, 2, 1, kBandHeight);
  job.params.row_begin = kBandFirstRow;
  job.camera = test_room_camera(kBandWidth, kBandHeight);
  return job;
}

// Each tracer this build has and this machine runs, with the test room applied, by name.
std::vector<std::pair<std::string, std::unique_ptr<core::Tracer>>> tracers_with_the_room() {
  auto room = std::make_shared<commit::TracerScene>(core::compile_scene(test_room()).tracer_scene);
  std::vector<std::pair<std::string, std::unique_ptr<core::Tracer>>> out;
  for (const std::string& kind : built_tracers()) {
    if (!tracer_runs_here(kind)) continue;
    auto tracer = make_test_tracer(kind);
    tracer->apply(commit::CommitBuffer::full(room, 1));
    out.emplace_back(kind, std::move(tracer));
  }
  return out;
}

}  // namespace

class Agreement : public ::testing::TestWithParam<Case> {};

TEST_P(Agreement, EmbreeAndOpenCLImagesMatch) {
  std::vector<std::string> names = built_tracers();
  if (names.size() < 2) GTEST_SKIP() << "needs both the Embree and the OpenCL tracer";
  if (!tracer_runs_here("opencl")) GTEST_SKIP() << "no OpenCL device here";
  const Case c = GetParam();
  scene::Scene room = test_room();
  const int w = 64, h = 48;
  KCamera cam = test_room_camera(w, h);
  KFrameParams params = agreement_params(c.mode, c.bounces, h);
  params.light_samples = c.light_samples;
  params.light_sampling = c.light_sampling;
  params.emissive_samples = c.emissive_samples;
  auto embree = make_test_tracer("embree");
  auto opencl = make_test_tracer("opencl");
  core::FrameBuffer a = render(*embree, room, cam, params);
  core::FrameBuffer b = render(*opencl, room, cam, params);
  for (float v : a.rgba) ASSERT_TRUE(std::isfinite(v)) << "embree wrote a non-finite value";
  for (float v : b.rgba) ASSERT_TRUE(std::isfinite(v)) << "opencl wrote a non-finite value";
  double mean = 0.0;
  double error = rgb_rmse(a, b, &mean);
  EXPECT_GT(mean, 0.01) << "the room should be lit";
  EXPECT_LT(error, 0.005 * mean) << c.name << ": RMSE " << error << " vs mean " << mean;

  // The same tracer with a different frame index draws different samples: the bound must be tighter
  // than that noise, or this test could not tell two tracers apart.
  KFrameParams other = params;
  other.frame_index = 8;
  core::FrameBuffer noise = render(*embree, room, cam, other);
  double noise_mean = 0.0;
  double noise_error = rgb_rmse(a, noise, &noise_mean);
  if (c.mode == K_MODE_PATH) {
    EXPECT_GT(noise_error, 2.0 * error) << "sample noise " << noise_error;
  }
  std::cout << c.name << ": RMSE embree/opencl " << error << ", frame-to-frame noise " << noise_error << ", mean "
            << mean << "\n";
  if (const char* dir = std::getenv("COHORT_TEST_IMAGES")) {
    write_preview(std::string(dir) + "/agreement_" + c.name + "_embree.png", a);
    write_preview(std::string(dir) + "/agreement_" + c.name + "_opencl.png", b);
  }
}

INSTANTIATE_TEST_SUITE_P(Modes, Agreement,
                         ::testing::Values(Case{K_MODE_PATH, 1, "path"}, Case{K_MODE_PATH, 3, "path3"},
                                           Case{K_MODE_PATH, 1, "path_all_lights", 0},
                                           Case{K_MODE_PATH, 1, "path_all_pick", 1, K_LIGHTS_ALL},
                                           Case{K_MODE_PATH, 1, "path_no_emissive_nee", 1, K_LIGHTS_TREE, 0},
                                           Case{K_MODE_PATH, 1, "path_gather", 2, K_LIGHTS_GATHER},
                                           Case{K_MODE_DIRECT, 0, "direct"}, Case{K_MODE_ALBEDO, 0, "albedo"},
                                           Case{K_MODE_NORMALS, 0, "normals"},
                                           // Embree draws its heat map on Cohort's own BVH, as OpenCL does.
                                           Case{K_MODE_BVH, 0, "bvh"}),
                         [](const auto& info) { return std::string(info.param.name); });

// The light tree's descent (more lights than K_LIGHT_TREE_GATHER overlap), the emissive-triangle
// sampling, gather's choice among more lights than its budget, the pick among every light in range and the
// dense rooms' descent by its guess give the same image on both tracers.
TEST(AgreementManyLights, EmbreeAndOpenCLImagesMatch) {
  std::vector<std::string> names = built_tracers();
  if (names.size() < 2 || !tracer_runs_here("opencl")) GTEST_SKIP() << "needs both the Embree and the OpenCL tracer";
  scene::Scene s = many_lights_floor(88, 8);
  const int w = 48, h = 36;
  const KCamera cam = camera_looking_down({0, 0, 1400}, 0.7f, w, h);
  KFrameParams params = frame_params(K_MODE_PATH, 8, 1, h);
  params.soft_shadow_scale = 1.0f;
  auto embree = make_test_tracer("embree");
  auto opencl = make_test_tracer("opencl");
  core::FrameBuffer a = render(*embree, s, cam, params);
  core::FrameBuffer b = render(*opencl, s, cam, params);
  double mean = 0.0;
  double error = rgb_rmse(a, b, &mean);
  std::cout << "many lights, tree: RMSE embree/opencl " << error << ", mean " << mean << "\n";
  EXPECT_GT(mean, 0.05);
  EXPECT_LT(error, 0.005 * mean);
  // Gather with fewer rays than lights in range: the systematic choice and its weights.
  params.light_sampling = K_LIGHTS_GATHER;
  params.light_samples = 4;
  a = render(*embree, s, cam, params);
  b = render(*opencl, s, cam, params);
  error = rgb_rmse(a, b, &mean);
  std::cout << "many lights, gather 4: RMSE embree/opencl " << error << ", mean " << mean << "\n";
  EXPECT_GT(mean, 0.05);
  EXPECT_LT(error, 0.005 * mean);
  // One light among every light in range of the point, without the tree's descent.
  params.light_sampling = K_LIGHTS_IN_RANGE;
  params.light_samples = 1;
  a = render(*embree, s, cam, params);
  b = render(*opencl, s, cam, params);
  error = rgb_rmse(a, b, &mean);
  std::cout << "many lights, in range: RMSE embree/opencl " << error << ", mean " << mean << "\n";
  EXPECT_GT(mean, 0.05);
  EXPECT_LT(error, 0.005 * mean);  // Dense rooms: the descent by k_light_node_guess to at most K_LIGHT_DENSE_LEAF lights, then in-range.
  params.light_sampling = K_LIGHTS_DENSE;
  a = render(*embree, s, cam, params);
  b = render(*opencl, s, cam, params);
  error = rgb_rmse(a, b, &mean);
  std::cout << "many lights, dense: RMSE embree/opencl " << error << ", mean " << mean << "\n";
  EXPECT_GT(mean, 0.05);
  EXPECT_LT(error, 0.005 * mean);
}

// A scene pack read back renders exactly like the scene it was written from.
TEST(ScenePack, RendersLikeTheCompiledScene) {
  if (!tracer_runs_here("embree")) GTEST_SKIP();
  core::PackedScene pack;
  pack.map_name = "test_room";
  scene::Scene room = test_room();
  core::CompiledScene compiled = core::compile_scene(room);
  pack.tracer_scene = compiled.tracer_scene;
  pack.blas_of_mesh = compiled.blas_of_mesh;
  pack.world_blas = compiled.world_blas;
  pack.instance_names.assign(pack.tracer_scene.instances.size(), "x");
  pack.player_start[0] = room.player_start.x;
  const char* keep = std::getenv("COHORT_TEST_IMAGES");
  std::filesystem::path file = keep ? std::filesystem::path(keep) / "test_room.cpack"
                                    : std::filesystem::temp_directory_path() / "cohort_test_room.cpack";
  core::write_scene_pack(file, pack);
  core::PackedScene back = core::read_scene_pack(file);
  if (!keep) std::filesystem::remove(file);
  const int w = 32, h = 24;
  KCamera cam = test_room_camera(w, h);
  KFrameParams params = frame_params(K_MODE_PATH, 4, 1, h);
  auto tracer = make_test_tracer("embree");
  core::FrameBuffer a = render(*tracer, room, cam, params);
  tracer->apply(commit::CommitBuffer::full(std::make_shared<commit::TracerScene>(back.tracer_scene), 2));
  core::FrameBuffer b;
  b.resize(w, h);
  core::BandJob job;
  job.params = params;
  job.camera = cam;
  tracer->render_band(job, b);
  EXPECT_EQ(a.rgba, b.rgba);
}

// The same comparison on the generated test map (assets/testmap), seen from the player start (every
// material class, entity, and light type it has) and from the sky court view (the sky, the chrome pipe's
// environment reflection, noSelfShadow leaves).
TEST(AgreementOnTestMap, EmbreeAndOpenCLImagesMatch) {
  std::vector<std::string> names = built_tracers();
  if (names.size() < 2 || !tracer_runs_here("opencl")) GTEST_SKIP() << "needs both the Embree and the OpenCL tracer";
  scene::Scene map = load_test_map();
  const int w = 64, h = 36;
  const KCamera cameras[2] = {
      core::make_camera(core::player_eye(map), {map.player_yaw, 0.0f}, core::kDefaultFovX, w, h),
      core::make_camera({1420, 364, 120}, {60.0f, -35.0f}, core::kDefaultFovX, w, h)};
  const KFrameParams params = testmap_agreement_params(h);
  auto embree = make_test_tracer("embree");
  auto opencl = make_test_tracer("opencl");
  for (const KCamera& cam : cameras) {
    core::FrameBuffer a = render(*embree, map, cam, params);
    core::FrameBuffer b = render(*opencl, map, cam, params);
    double mean = 0.0;
    double error = rgb_rmse(a, b, &mean);
    std::cout << "testmap on " << opencl->name() << ": RMSE embree/opencl " << error << ", mean " << mean << "\n";
    EXPECT_GT(mean, 0.01);
    EXPECT_LT(error, 0.005 * mean);
  }
}

// Every tracer this machine runs writes the same planes as Embree for the test room (a known scene with
// entities, textures, layers and an alpha-tested grate), from centre rays and from the paths' first hits.
class AgreementAux : public ::testing::TestWithParam<kuint> {};

TEST_P(AgreementAux, EveryTracerWritesEmbreesAuxPlanes) {
  const kuint aux_mode = GetParam();
  const KCamera cam = test_room_camera(64, 40);
  KCamera prev = core::make_camera({-180, -130, 125}, {33.0f, 21.0f}, 90.0f, 64, 40);
  auto room = std::make_shared<commit::TracerScene>(core::compile_scene(test_room()).tracer_scene);
  auto embree = make_test_tracer("embree");
  const core::GBuffer a = render_aux(*embree, room, 1, cam, prev, aux_mode);
  int checked = 0;
  for (const std::string& kind : built_tracers()) {
    if (kind == "embree" || !tracer_runs_here(kind)) continue;
    auto other = make_test_tracer(kind);
    const core::GBuffer b = render_aux(*other, room, 1, cam, prev, aux_mode);
    size_t id_mismatch = 0;
    for (size_t p = 0; p < a.pixels(); ++p) {
      if (a.id[p] != b.id[p]) { ++id_mismatch; continue; }  // a silhouette pixel may go either way
      EXPECT_TRUE(aux_planes_agree(a, b, p)) << kind << " pixel " << p;
    }
    EXPECT_LE(id_mismatch, a.pixels() / 100) << kind;
    ++checked;
  }
  if (checked == 0) GTEST_SKIP() << "no tracer besides Embree runs here";
}

INSTANTIATE_TEST_SUITE_P(Modes, AgreementAux, ::testing::Values(K_AUX_CENTRE_RAY, K_AUX_PATH_FIRST_HIT),
                         [](const ::testing::TestParamInfo<kuint>& info) {
                           return std::string(info.param == K_AUX_CENTRE_RAY ? "CentreRays" : "FirstHits");
                         });

// A band in half floats (`--band-format rgb16f`: GPU tracers convert it on the device) equals the same
// tracer's band in floats within half precision.
TEST(AgreementBandFormat, HalfFloatBandsEqualFloatBands) {
  const int w = kBandWidth, h = kBandHeight;
  const core::BandJob job = room_band_job();
  int checked = 0;
  for (auto& [kind, tracer] : tracers_with_the_room()) {
    core::FrameBuffer as_float, as_half;
    for (auto [format, out] : {std::pair{core::BandFormat::rgba32f, &as_float}, std::pair{core::BandFormat::rgb16f, &as_half}}) {
      core::BandBuffer band(w, h, format);
      tracer->render_band(job, band);
      out->resize(w, h);
      band.copy_rows_to(*out, 0, h);
    }
    double lit = 0.0;
    for (int y = kBandFirstRow; y < h; ++y)
      for (int x = 0; x < w; ++x)
        for (int k = 0; k < 3; ++k) {
          const float f = as_float.row(y)[4 * x + k], v = as_half.row(y)[4 * x + k];
          ASSERT_NEAR(v, f, 1e-3f * std::fabs(f) + 1e-6f) << kind << " pixel " << x << "," << y;
          lit += f;
        }
    EXPECT_GT(lit, 0.0) << kind << " rendered a black band";
    ++checked;
  }
  EXPECT_GT(checked, 0);
}

// A band in RGB9E5 (kernel/band_pack.h) is, word for word, the host's packing of the same tracer's float
// band with the same dither (pixel and frame): every producer (CUDA and OpenCL kernels, the host for
// Embree) packs alike, and the band is within one step (under 1/255.5 of the pixel's brightest channel) of the floats.
TEST(AgreementBandFormat, Rgb9e5BandsArePackedAlikeByEveryTracer) {
  const int w = kBandWidth, h = kBandHeight;
  core::BandJob job = room_band_job();
  job.params.frame_index = 37;
  int checked = 0;
  for (auto& [kind, tracer] : tracers_with_the_room()) {
    core::BandBuffer floats(w, h, core::BandFormat::rgba32f), packed(w, h, core::BandFormat::rgb9e5);
    tracer->render_band(job, floats);
    tracer->render_band(job, packed);
    const size_t band_pixels = size_t(w) * size_t(h - kBandFirstRow);
    std::vector<uint32_t> want(band_pixels);
    core::rgba32f_to_rgb9e5(static_cast<const float*>(floats.row(kBandFirstRow)), want.data(), band_pixels,
                            kuint(kBandFirstRow * w), 37u);
    const uint32_t* got = static_cast<const uint32_t*>(packed.row(kBandFirstRow));
    size_t differ = 0;
    for (size_t p = 0; p < band_pixels; ++p) differ += got[p] != want[p];
    EXPECT_EQ(differ, 0u) << kind << ": words that differ from the host's packing of its float band";
    core::FrameBuffer back;
    back.resize(w, h);
    packed.copy_rows_to(back, kBandFirstRow, h);
    double lit = 0.0;
    for (int y = kBandFirstRow; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const float* f = static_cast<const float*>(floats.row(y)) + 4 * x;
        const float top = std::max({f[0], f[1], f[2]});
        for (int k = 0; k < 3; ++k) {
          ASSERT_NEAR(back.row(y)[4 * x + k], f[k], top / 255.5f + 1e-6f) << kind << " pixel " << x << "," << y;
          lit += f[k];
        }
      }
    EXPECT_GT(lit, 0.0) << kind << " rendered a black band";
    ++checked;
  }
  EXPECT_GT(checked, 0);
}
