// The CUDA tracer against the CPU tracers. Skipped, with the reason, where no GPU exists (CI); run on
// the GPU machine through tools/gpu_run.sh.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <optional>
#include <stdexcept>
#include <vector>

#include "cohort/core/gpu_scene.h"
#include "cohort/core/scene_pack.h"
#include "cohort/core/view.h"
#include "shadow_walk_cases.h"
#include "test_scenes.h"
#include "test_tracers.h"

#ifdef COHORT_HAVE_CUDA

#include "cohort/tracers/cuda_tracer.h"

using namespace cohort;
using namespace cohort::test;

namespace {

// clamp_at: compare values clamped to the displayable range, so that one path that floating-point
// differences (nvcc fuses multiply-adds) sent another way cannot dominate as a single HDR outlier.
double relative_rmse(const core::FrameBuffer& a, const core::FrameBuffer& b, double clamp_at = 1e30) {
  double sum = 0.0, sum_sq = 0.0;
  size_t n = 0;
  for (size_t i = 0; i < a.rgba.size(); ++i) {
    if (i % 4 == 3) continue;
    double va = std::min(double(a.rgba[i]), clamp_at), vb = std::min(double(b.rgba[i]), clamp_at);
    double d = va - vb;
    sum_sq += d * d;
    sum += 0.5 * (va + vb);
    ++n;
  }
  double mean = sum / double(n);
  return mean > 0.0 ? std::sqrt(sum_sq / double(n)) / mean : 0.0;
}

core::FrameBuffer render_scene(core::Tracer& tracer, const commit::TracerScene& scene, const KCamera& cam,
                               const KFrameParams& params) {
  tracer.apply(commit::CommitBuffer::full(std::make_shared<commit::TracerScene>(scene), 1));
  return render_frame(tracer, cam, params);
}

// The packed map named by COHORT_PACK (eye height above its player start, along its yaw, as `cohort render`
// looks) or, with none, the test room; w x h pixels.
struct TestView {
  commit::TracerScene scene;
  KCamera camera;
};
TestView pack_or_room(const char* pack_file, int w, int h) {
  TestView v;
  if (pack_file) {
    core::PackedScene pack = core::read_scene_pack(pack_file);
    v.scene = pack.tracer_scene;
    glm::vec3 eye(pack.player_start[0], pack.player_start[1], pack.player_start[2] + core::kPlayerEyeHeight);
    v.camera = core::make_camera(eye, {pack.player_yaw, 0.0f}, core::kDefaultFovX, w, h);
  } else {
    v.scene = core::compile_scene(test_room()).tracer_scene;
    v.camera = test_room_camera(w, h);
  }
  return v;
}

#define REQUIRE_GPU()                                                                                   \
  if (tracers::cuda_device_count() == 0) GTEST_SKIP() << "no CUDA device on this machine (run tools/gpu_run.sh)"

struct ModeCase {
  uint32_t mode, bounces;
  const char* name;
  uint32_t light_samples = 1;
  uint32_t light_sampling = K_LIGHTS_TREE;
};

class CudaAgreement : public ::testing::TestWithParam<ModeCase> {};

// Same bound as the Embree/OpenCL agreement test: RMSE below 0.5% of the mean at 16 spp.
TEST_P(CudaAgreement, MatchesEmbree) {
  REQUIRE_GPU();
  const ModeCase c = GetParam();
  scene::Scene room = test_room();
  const int w = 64, h = 48;
  KCamera cam = test_room_camera(w, h);
  KFrameParams params = agreement_params(c.mode, c.bounces, h);
  params.light_samples = c.light_samples;
  params.light_sampling = c.light_sampling;
  auto embree = make_test_tracer("embree");
  auto cuda = make_test_tracer("cuda");
  core::FrameBuffer a = render(*embree, room, cam, params);
  core::FrameBuffer b = render(*cuda, room, cam, params);
  for (float v : b.rgba) ASSERT_TRUE(std::isfinite(v));
  double error = relative_rmse(a, b);
  std::cout << c.name << ": relative RMSE embree/cuda " << error << "\n";
  EXPECT_LT(error, 0.005) << c.name;
  if (const char* dir = std::getenv("COHORT_TEST_IMAGES")) {
    write_preview(std::string(dir) + "/cuda_" + c.name + "_embree.ppm", a);
    write_preview(std::string(dir) + "/cuda_" + c.name + "_cuda.ppm", b);
  }
}

INSTANTIATE_TEST_SUITE_P(Modes, CudaAgreement,
                         ::testing::Values(ModeCase{K_MODE_PATH, 1, "path"}, ModeCase{K_MODE_PATH, 3, "path3"},
                                           ModeCase{K_MODE_DIRECT, 0, "direct"}, ModeCase{K_MODE_ALBEDO, 0, "albedo"},
                                           ModeCase{K_MODE_PATH, 1, "path_gather", 2, K_LIGHTS_GATHER}),
                         [](const auto& info) { return std::string(info.param.name); });

// Under 96 overlapping lights (the tree descends, gather has more lights in range than its budget, the pick
// in range weighs them all, the dense pick descends by its guess in kernels of their own,
// render_band_dense.cu), CUDA draws Embree's image, as AgreementManyLights checks for OpenCL.
TEST(CudaAgreementManyLights, MatchesEmbree) {
  REQUIRE_GPU();
  scene::Scene s = many_lights_floor(88, 8);
  const int w = 48, h = 36;
  const KCamera cam = camera_looking_down({0, 0, 1400}, 0.7f, w, h);
  auto embree = make_test_tracer("embree");
  auto cuda = make_test_tracer("cuda");
  for (kuint sampling : {K_LIGHTS_TREE, K_LIGHTS_GATHER, K_LIGHTS_IN_RANGE, K_LIGHTS_DENSE}) {
    KFrameParams params = frame_params(K_MODE_PATH, 8, 1, h);
    params.soft_shadow_scale = 1.0f;
    params.light_sampling = sampling;
    params.light_samples = sampling == K_LIGHTS_GATHER ? 4u : 1u;
    core::FrameBuffer a = render(*embree, s, cam, params);
    core::FrameBuffer b = render(*cuda, s, cam, params);
    for (float v : b.rgba) ASSERT_TRUE(std::isfinite(v));
    double error = relative_rmse(a, b);
    std::cout << "many lights, sampling " << sampling << ": relative RMSE embree/cuda " << error << "\n";
    EXPECT_LT(error, 0.005) << "sampling " << sampling;
  }
}

// Several GPUs render different bands of one frame; the merged frame equals one GPU's whole frame.
TEST(CudaMultiGpu, BandsMergeIntoTheSingleGpuFrame) {
  const int gpus = tracers::cuda_device_count();
  if (gpus < 2) GTEST_SKIP() << "needs at least 2 CUDA devices, found " << gpus;
  scene::Scene room = test_room();
  core::CompiledScene compiled = core::compile_scene(room);
  const int w = 96, h = 64;
  KCamera cam = test_room_camera(w, h);
  KFrameParams params = frame_params(K_MODE_PATH, 4, 1, h);
  tracers::CudaTracer single(0);
  core::FrameBuffer whole = render_scene(single, compiled.tracer_scene, cam, params);

  core::FrameBuffer merged;
  merged.resize(w, h);
  std::vector<std::unique_ptr<tracers::CudaTracer>> per_gpu;
  for (int g = 0; g < gpus; ++g) {
    per_gpu.push_back(std::make_unique<tracers::CudaTracer>(g));
    per_gpu.back()->apply(commit::CommitBuffer::full(std::make_shared<commit::TracerScene>(compiled.tracer_scene), 1));
  }
  const int rows_per_gpu = (h / gpus + 3) / 4 * 4;   // bands in whole work units of 4 rows
  for (int g = 0; g < gpus; ++g) {
    core::BandJob job;
    job.params = params;
    job.camera = cam;
    job.params.row_begin = uint32_t(std::min(h, g * rows_per_gpu));
    job.params.row_end = uint32_t(g == gpus - 1 ? h : std::min(h, (g + 1) * rows_per_gpu));
    per_gpu[size_t(g)]->render_band(job, merged);
  }
  // Same integrator, same random numbers, same GPU model: the results agree to rounding.
  double error = relative_rmse(whole, merged);
  EXPECT_LT(error, 1e-4) << "relative RMSE " << error;
}

// A scene pack renders on the GPU like the scene compiled in memory, and (when COHORT_PACK names the
// packed test map, as tools/gpu_run.sh does) the packed map renders on CUDA like on Embree.
TEST(CudaScenePack, PackedSceneMatchesEmbree) {
  REQUIRE_GPU();
  const char* pack_file = std::getenv("COHORT_PACK");
  const int w = 128, h = 72;
  const TestView view = pack_or_room(pack_file, w, h);
  const commit::TracerScene& scene = view.scene;
  const KCamera& cam = view.camera;
  // 64 spp: on the full map (8 lights, textures, glass) a few samples per thousand take another path
  // on the GPU (fused multiply-adds shift a light pick or a Russian roulette decision); at 16 spp those
  // alone came to 0.5% RMSE, at 64 they average down below the bound.
  KFrameParams params = frame_params(K_MODE_PATH, 64, 1, h);
  params.frame_index = 3;
  auto embree = make_test_tracer("embree");
  auto cuda = make_test_tracer("cuda");
  core::FrameBuffer a = render_scene(*embree, scene, cam, params);
  core::FrameBuffer b = render_scene(*cuda, scene, cam, params);
  // Compared in the displayable range, with the same 0.5% bound as everywhere else.
  double error = relative_rmse(a, b, 1.0);
  std::cout << (pack_file ? pack_file : "test room") << ": relative RMSE embree/cuda (clamped at 1) " << error
            << ", unclamped " << relative_rmse(a, b) << "\n";
  EXPECT_LT(error, 0.005);
  if (const char* dir = std::getenv("COHORT_TEST_IMAGES")) {
    write_preview(std::string(dir) + "/pack_embree.ppm", a);
    write_preview(std::string(dir) + "/pack_cuda.ppm", b);
  }
}


// The wavefront (bounce rays walked by a kernel of their own, the paths in memory between kernels) draws
// the megakernel's image: same integrator, same random numbers; over several bounces, Russian roulette,
// several samples a pixel, the first-hit records of the aux planes, and a band that starts mid-frame.
struct WavefrontCase {
  uint32_t bounces, spp;
  bool pack;
  const char* name;
  uint32_t path_pixels = 0;  // dynamic resolution's sparse pattern: paths at this many of each 16 pixels
};
class CudaWavefront : public ::testing::TestWithParam<WavefrontCase> {};

TEST_P(CudaWavefront, DrawsTheMegakernelsImage) {
  REQUIRE_GPU();
  const WavefrontCase c = GetParam();
  const char* pack_file = std::getenv("COHORT_PACK");
  if (c.pack && !pack_file) GTEST_SKIP() << "COHORT_PACK names no packed map (tools/gpu_run.sh sets it)";
  const int w = 96, h = 64;
  const TestView view = pack_or_room(c.pack ? pack_file : nullptr, w, h);
  const commit::TracerScene& scene = view.scene;
  const KCamera& cam = view.camera;
  KFrameParams params = frame_params(K_MODE_PATH, c.spp, c.bounces, h);
  params.rr_start = 2.0f;
  params.frame_index = 5;
  params.aux_outputs = K_AUX_PATH_FIRST_HIT;  // centre rays under the sparse pattern, in both
  params.path_pixels = c.path_pixels;
  params.path_phase = 3;
  core::BandBuffer frames[2];
  for (int wavefront = 0; wavefront < 2; ++wavefront) {
    tracers::CudaTracer cuda(0);
    cuda.set_wavefront(wavefront == 1);
    cuda.set_ray_counting(true);
    cuda.apply(commit::CommitBuffer::full(std::make_shared<commit::TracerScene>(scene), 1));
    frames[wavefront].resize(w, h, core::BandFormat::rgba32f);
    frames[wavefront].enable_aux(true);
    for (int band = 0; band < 2; ++band) {  // the second band starts mid-frame
      core::BandJob job;
      job.params = params;
      job.camera = cam;
      job.params.row_begin = band == 0 ? 0u : 24u;
      job.params.row_end = band == 0 ? 24u : uint32_t(h);
      cuda.render_band(job, frames[wavefront]);
    }
    const auto counts = cuda.last_ray_counts();
    EXPECT_GT(counts.closest, 0u) << (wavefront ? "wavefront" : "megakernel") << " counts its rays";
  }
  core::FrameBuffer a, b;
  a.resize(w, h);
  b.resize(w, h);
  frames[0].copy_rows_to(a, 0, h);
  frames[1].copy_rows_to(b, 0, h);
  for (float v : b.rgba) ASSERT_TRUE(std::isfinite(v));
  const double error = relative_rmse(a, b, 1.0);
  std::cout << c.name << ": relative RMSE megakernel/wavefront " << error << "\n";
  EXPECT_EQ(error, 0.0) << c.name << ": the same integrator, random numbers and float operations";
  size_t same_ids = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) same_ids += frames[0].aux_row(y)[x].id == frames[1].aux_row(y)[x].id;
  EXPECT_GE(double(same_ids), 0.999 * w * h) << "the first-hit records agree";
}

INSTANTIATE_TEST_SUITE_P(Paths, CudaWavefront,
                         ::testing::Values(WavefrontCase{1, 1, false, "room_bounce1"},
                                           WavefrontCase{3, 2, false, "room_bounce3_spp2"},
                                           WavefrontCase{2, 3, false, "room_bounce2_spp3"},
                                           WavefrontCase{1, 1, true, "pack_bounce1"},
                                           WavefrontCase{2, 4, true, "pack_bounce2_spp4"},
                                           WavefrontCase{1, 1, true, "pack_sparse4", 4},
                                           WavefrontCase{2, 2, false, "room_sparse8_spp2", 8}),
                         [](const auto& info) { return std::string(info.param.name); });

// The wavefront's lanes (CudaTracer::set_wave_lanes: a band's rows split over streams) change only where
// kernels run: the image, the first-hit planes, the ray counts and the per-row work are those of one lane,
// exactly, for bands that start mid-frame and split unevenly.
TEST(CudaWaveLanes, DrawTheImageOfOneLane) {
  REQUIRE_GPU();
  const char* pack_file = std::getenv("COHORT_PACK");
  const int w = 64, h = 200;
  const TestView view = pack_or_room(pack_file, w, h);
  KFrameParams params = frame_params(K_MODE_PATH, 2, 2, h);
  params.frame_index = 7;
  params.aux_outputs = K_AUX_PATH_FIRST_HIT;
  core::BandBuffer frames[4];
  std::vector<float> work[4];
  tracers::CudaTracer::RayCounts counts[4];
  for (int lanes = 1; lanes <= 4; ++lanes) {
    tracers::CudaTracer cuda(0);
    cuda.set_wave_lanes(lanes);
    cuda.set_ray_counting(true);
    cuda.apply(commit::CommitBuffer::full(std::make_shared<commit::TracerScene>(view.scene), 1));
    core::BandBuffer& frame = frames[lanes - 1];
    frame.resize(w, h, core::BandFormat::rgba32f);
    frame.enable_aux(true);
    for (int band = 0; band < 2; ++band) {  // 75 rows (two lanes at most), then 125 from mid-frame (three)
      core::BandJob job;
      job.params = params;
      job.camera = view.camera;
      job.params.row_begin = band == 0 ? 0u : 75u;
      job.params.row_end = band == 0 ? 75u : uint32_t(h);
      const core::BandResult result = cuda.render_band(job, frame);
      work[lanes - 1].insert(work[lanes - 1].end(), result.row_work.begin(), result.row_work.end());
    }
    counts[lanes - 1] = cuda.last_ray_counts();
  }
  EXPECT_THROW(tracers::CudaTracer(0).set_wave_lanes(5), std::invalid_argument);
  for (int lanes = 2; lanes <= 4; ++lanes) {
    for (int y = 0; y < h; ++y) {
      ASSERT_EQ(std::memcmp(frames[lanes - 1].row(y), frames[0].row(y), frames[0].row_bytes()), 0)
          << lanes << " lanes, row " << y;
      ASSERT_EQ(std::memcmp(frames[lanes - 1].aux_row(y), frames[0].aux_row(y), sizeof(KAuxTexel) * w), 0)
          << lanes << " lanes, aux row " << y;
    }
    EXPECT_EQ(work[lanes - 1], work[0]) << lanes << " lanes";
    EXPECT_EQ(counts[lanes - 1].closest, counts[0].closest) << lanes << " lanes";
    EXPECT_EQ(counts[lanes - 1].occlusion, counts[0].occlusion) << lanes << " lanes";
  }
}

// Enqueue ahead (CudaTracer::set_enqueue_ahead) with the Renderer's queued_next hook played by the test: the
// second of three bands' jobs is queued while the first renders, none after. The second goes ahead and its
// job takes it; its image, rows and ray counts are those of the same band enqueued when its job came (the
// option off). The balancer's cost: the first band (the second went ahead inside it) and the third (its job
// came late) cost their wall time less their enqueueing, the one that went ahead its wall time
// (BandResult::balance_ms 0); with the option off every band its wall time.
TEST(CudaEnqueueAhead, TakesTheBandItsJobFindsEnqueuedAndCostsALateOneLessItsEnqueueing) {
  REQUIRE_GPU();
  const int w = 96, h = 64;
  const TestView view = pack_or_room(std::getenv("COHORT_PACK"), w, h);
  struct Run {
    core::BandBuffer target;
    std::vector<core::BandResult> results;
    std::vector<double> wall_ms;
    size_t enqueued = 0, finished = 0;
  };
  auto run = [&](bool ahead) {
    tracers::CudaTracer cuda(0);
    cuda.set_enqueue_ahead(ahead);
    cuda.set_ray_counting(true);
    cuda.apply(commit::CommitBuffer::full(std::make_shared<commit::TracerScene>(view.scene), 1));
    Run r;
    r.target.resize(w, h, core::BandFormat::rgba32f);
    std::vector<core::BandJob> jobs(3);
    for (kuint f = 0; f < 3; ++f) {
      jobs[f].params = frame_params(K_MODE_PATH, 1, 1, h);
      jobs[f].params.frame_index = f;
      jobs[f].params.row_begin = f == 1 ? 8u : 0u;  // the second band a part of the frame
      jobs[f].params.row_end = f == 1 ? 40u : uint32_t(h);
      jobs[f].camera = view.camera;
    }
    int handed = 0;
    cuda.set_queued_next(
        [&](const core::Tracer::BandDone&) -> std::optional<core::Tracer::QueuedNext> {
          if (handed++ > 0) return std::nullopt;
          return core::Tracer::QueuedNext{jobs[1], &r.target};
        },
        [] {});
    std::vector<float> second;
    for (const core::BandJob& job : jobs) {
      const auto start = std::chrono::steady_clock::now();
      r.results.push_back(cuda.render_band(job, r.target));
      r.wall_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
      if (r.results.size() == 2) {  // the second band's rows, before the third overwrites them
        const float* rows = static_cast<const float*>(r.target.row(8));
        second.assign(rows, rows + size_t(32) * w * 4);
      }
    }
    std::memcpy(r.target.row(8), second.data(), second.size() * sizeof(float));
    r.enqueued = cuda.bands_enqueued_ahead();
    r.finished = cuda.bands_finished_ahead();
    return r;
  };
  const Run on = run(true), off = run(false);
  ASSERT_EQ(on.enqueued, 1u) << "the second band should have gone ahead";
  EXPECT_EQ(on.finished, 1u) << "its job should have found it enqueued";
  EXPECT_EQ(off.enqueued, 0u);
  EXPECT_EQ(std::memcmp(on.target.row(8), off.target.row(8), size_t(32) * on.target.row_bytes()), 0)
      << "the band that went ahead draws what it draws enqueued at its job";
  EXPECT_EQ(on.results[1].row_work, off.results[1].row_work);
  EXPECT_GT(on.results[1].device_ms, 0.0);
  EXPECT_GT(on.results[0].balance_ms, 0.0);
  EXPECT_EQ(on.results[1].balance_ms, 0.0) << "a band that went ahead costs its wall time";
  EXPECT_GT(on.results[2].balance_ms, 0.0) << "a band whose job came late costs less than its wall time";
  EXPECT_LT(on.results[2].balance_ms, on.wall_ms[2]);
  for (const core::BandResult& r : off.results) EXPECT_EQ(r.balance_ms, 0.0) << "option off";
}

// Next-event estimation's shadow rays walked by a kernel of their own (CudaTracer::set_shadow_walk): the
// image of the wavefront that walks them in its shading kernels bit for bit, the megakernel's, and the same
// rays counted. On a floor of 96 lights (or 6) and an emissive panel, two samples, two bounces, soft
// shadows: gather chooses among more lights than its budget, two light samples average with the shadow
// roulette on, `every` with 6 lights leaves 7 rays a vertex, with 96 more than a vertex's slots (then the
// shading kernels walk them), and the firefly clamp works on the vertex's sum.
class CudaShadowWalk : public ::testing::TestWithParam<ShadowWalkCase> {};

TEST_P(CudaShadowWalk, DrawsTheImageOfShadowsWalkedInTheShadingKernels) {
  REQUIRE_GPU();
  const ShadowWalkCase c = GetParam();
  const int w = 64, h = 48;
  const KCamera cam = camera_looking_down({0, 0, 1400}, 0.7f, w, h);
  const KFrameParams params = shadow_walk_params(c, h);
  scene::Scene floor = many_lights_floor_under_a_panel(c.point_lights, c.projected_lights);
  auto scene = std::make_shared<commit::TracerScene>(core::compile_scene(floor).tracer_scene);
  ASSERT_EQ(scene->emissive_triangles.size(), 2u) << "the panel's triangles are emitters to sample";
  struct Variant {
    bool wavefront, shadow_walk;
    const char* name;
  };
  const Variant variants[3] = {
      {false, false, "megakernel"}, {true, false, "shadows in the shading kernels"}, {true, true, "shadow walk"}};
  core::FrameBuffer frames[3];
  tracers::CudaTracer::RayCounts counts[3];
  for (int v = 0; v < 3; ++v) {
    tracers::CudaTracer cuda(0);
    cuda.set_wavefront(variants[v].wavefront);
    cuda.set_shadow_walk(variants[v].shadow_walk);
    cuda.set_ray_counting(true);
    cuda.apply(commit::CommitBuffer::full(scene, 1));
    frames[v] = render_frame(cuda, cam, params);
    counts[v] = cuda.last_ray_counts();
    for (float x : frames[v].rgba) ASSERT_TRUE(std::isfinite(x)) << variants[v].name;
  }
  size_t differing = 0;
  for (size_t i = 0; i < frames[1].rgba.size(); ++i) differing += frames[1].rgba[i] != frames[2].rgba[i];
  EXPECT_EQ(differing, 0u) << c.name << ": floats that differ between the shadow walk and the shading kernels'";
  double mean = 0.0;
  const double error = rgb_rmse(frames[0], frames[2], &mean);
  std::cout << c.name << ": mean " << mean << ", RMSE megakernel/shadow walk " << error << ", floats differing from "
            << "the shading kernels' shadows " << differing << ", occlusion rays " << counts[2].occlusion << "\n";
  EXPECT_GT(mean, 0.0) << c.name << ": the floor is lit";
  EXPECT_LE(error, 1e-4 * mean) << c.name;
  EXPECT_GT(counts[2].occlusion, 0u) << c.name;
  for (int v = 0; v < 2; ++v) {
    EXPECT_EQ(counts[v].closest, counts[2].closest) << c.name << ": " << variants[v].name;
    EXPECT_EQ(counts[v].occlusion, counts[2].occlusion) << c.name << ": " << variants[v].name;
  }
}

INSTANTIATE_TEST_SUITE_P(LightSampling, CudaShadowWalk, ::testing::ValuesIn(shadow_walk_cases()),
                         [](const auto& info) { return std::string(info.param.name); });

}  // namespace

#else

TEST(Cuda, NotBuilt) { GTEST_SKIP() << "this build has no CUDA tracer (nvcc not found or COHORT_WITH_CUDA=OFF)"; }

#endif
