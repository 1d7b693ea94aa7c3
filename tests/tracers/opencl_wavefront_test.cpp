// The OpenCL tracer's wavefront (OpenCLTracer::Options::wavefront: walks and shading in kernels of their own,
// the paths in device memory between them) draws the megakernel's image bit for bit: same integrator, same
// random numbers, same order of float operations. Every float of the band, every aux texel, and the rays
// counted per row must be the megakernel's, on the test room and the test map, over several bounces,
// Russian roulette, 2, 3 and 4 samples a pixel, bands that start mid-frame, the first-hit records of the aux
// planes (in pieces), the sparse pattern of dynamic resolution, and a floor of many lights, whose shadow rays
// go to the shadow walk where they fit a vertex's slots and stay in the shading kernels where they do not.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "cohort/core/view.h"
#include "cohort/tracers/device_listing.h"
#include "cohort/scene/map_loader.h"
#include "band_frames.h"
#include "shadow_walk_cases.h"
#include "test_scenes.h"
#include "test_tracers.h"

#ifdef COHORT_HAVE_OPENCL
#include "cohort/tracers/opencl_tracer.h"
#endif

using namespace cohort;
using namespace cohort::test;

#ifdef COHORT_HAVE_OPENCL

namespace {

struct Variant {
  bool wavefront, shadow_walk;
  int pieces;  // the first-hit pieces (Options::first_hit_pieces)
  const char* name;
  bool lanes = true;  // Options::wave_lanes
  tracers::OpenCLTracer::Options::TransferQueue transfer = tracers::OpenCLTracer::Options::TransferQueue::on_gpus;
};
const Variant kMegakernel{false, true, 1, "megakernel"};
const Variant kWavefront{true, true, 4, "wavefront"};
const Variant kShadowsInTheShadingKernels{true, false, 2, "wavefront, shadow rays in the shading kernels"};

std::unique_ptr<tracers::OpenCLTracer> opencl(const Variant& v) {
  tracers::OpenCLTracer::Options options;
  options.device = test_opencl_device();
  options.wavefront = v.wavefront ? tracers::OpenCLTracer::Options::Wavefront::always
                                  : tracers::OpenCLTracer::Options::Wavefront::never;
  options.shadow_walk = v.shadow_walk;
  options.first_hit_pieces = v.pieces;
  options.wave_lanes = v.lanes;
  options.transfer_queue = v.transfer;
  return std::make_unique<tracers::OpenCLTracer>(options);
}

// The frame rendered band by band by a tracer of variant v (render_in_bands).
BandFrame render_bands(const Variant& v, const View& view, const KFrameParams& params, const std::vector<int>& cuts) {
  auto tracer = opencl(v);
  return render_in_bands(*tracer, view, params, cuts);
}

// The wavefront's frame against the megakernel's: every float, aux texel and row count the same.
void expect_the_megakernels_frame(const Variant& v, const View& view, const KFrameParams& params,
                                  const std::vector<int>& cuts, const std::string& what) {
  SCOPED_TRACE(what + ", " + v.name);
  BandFrame mega = render_bands(kMegakernel, view, params, cuts);
  BandFrame wave = render_bands(v, view, params, cuts);
  expect_same_band_frame(mega.frame, mega.row_work, wave.frame, wave.row_work, params.aux_outputs != 0u,
                         int(view.camera.height), "the megakernel's");
  EXPECT_GT(wave.device_ms, 0.0);
}

struct SceneCase {
  bool map;
  uint32_t bounces, spp;
  const char* name;
  float rr_start = 2.0f;
  kuint aux = 0u;              // K_AUX_PATH_FIRST_HIT: the first-hit records (centre rays under the sparse pattern)
  uint32_t path_pixels = 0u;   // dynamic resolution's sparse pattern: paths at this many of each 16 pixels
  uint32_t light_sampling = K_LIGHTS_TREE;
  std::vector<int> cuts = {};  // the bands (default: two, the second from row 13)
};
void PrintTo(const SceneCase& c, std::ostream* os) { *os << c.name; }
class OpenCLWavefront : public ::testing::TestWithParam<SceneCase> {};

TEST_P(OpenCLWavefront, DrawsTheMegakernelsImage) {
  if (!tracer_runs_here("opencl")) GTEST_SKIP() << "no OpenCL device here";
  const SceneCase c = GetParam();
  const int w = 40, h = 32;
  const View view = c.map ? map_view(w, h) : room_view(w, h);
  const KFrameParams params =
      wave_case_params(K_MODE_PATH, c.spp, c.bounces, h, c.rr_start, c.aux, c.path_pixels, c.light_sampling);
  const std::vector<int> cuts = c.cuts.empty() ? std::vector<int>{0, 13, h} : c.cuts;
  expect_the_megakernels_frame(kWavefront, view, params, cuts, c.name);
}

// The wavefront's two lanes (Options::wave_lanes: on a GPU device, a band of 64 rows or more split over two
// queues) change only where kernels run: against one lane every float, aux texel and row count is the same,
// for bands that start mid-frame and split off the middle, with and without the first-hit records.
TEST(OpenCLWaveLanes, DrawTheImageOfOneLane) {
  int gpu = -1;  // the first OpenCL GPU device (lanes are for GPUs only)
  const std::vector<tracers::TracerDevice> devices = tracers::list_tracer_devices();
  for (const tracers::TracerDevice& d : devices)
    if (gpu < 0 && d.tracer.rfind("opencl:", 0) == 0 && d.kind == tracers::DeviceKind::gpu)
      gpu = std::atoi(d.tracer.c_str() + 7);
  if (gpu < 0) GTEST_SKIP() << "no OpenCL GPU device here (lanes run on GPUs only)";
  ::setenv("COHORT_TEST_OPENCL_DEVICE", std::to_string(gpu).c_str(), 1);
  const int w = 24, h = 150;
  const View view = room_view(w, h);
  for (kuint aux : {0u, kuint(K_AUX_PATH_FIRST_HIT)}) {
    KFrameParams params = frame_params(K_MODE_PATH, 2, 2, h);
    params.frame_index = 9;
    params.aux_outputs = aux;
    const Variant one_lane{true, true, 1, "one lane", false};
    const Variant two_lanes{true, true, 1, "two lanes", true};
    const std::vector<int> cuts = {0, 5, 85, h};  // 80 rows (lanes of 40), 65 (32 and 33)
    BandFrame one = render_bands(one_lane, view, params, cuts);
    BandFrame two = render_bands(two_lanes, view, params, cuts);
    SCOPED_TRACE(aux ? "first-hit records" : "no aux planes");
    EXPECT_EQ(differing_floats(one.frame, two.frame), 0u);
    if (aux) {
      EXPECT_EQ(std::memcmp(one.frame.aux_data(), two.frame.aux_data(), one.frame.aux_bytes()), 0) << "aux planes";
    }
    EXPECT_EQ(two.row_work, one.row_work);
    EXPECT_GT(two.device_ms, 0.0) << "the join is timed";
  }
  ::unsetenv("COHORT_TEST_OPENCL_DEVICE");
}

INSTANTIATE_TEST_SUITE_P(
    Paths, OpenCLWavefront,
    ::testing::Values(SceneCase{false, 1, 1, "room_bounce1"},
                      SceneCase{false, 3, 2, "room_bounce3_spp2_roulette", 1.0f},
                      SceneCase{false, 2, 3, "room_bounce2_spp3"},
                      SceneCase{false, 2, 2, "room_first_hits_bands_mid_frame", 2.0f, K_AUX_PATH_FIRST_HIT, 0u,
                                K_LIGHTS_TREE, {0, 5, 21, 32}},
                      SceneCase{false, 2, 2, "room_sparse8_spp2", 2.0f, K_AUX_PATH_FIRST_HIT, 8u},
                      SceneCase{true, 1, 1, "map_bounce1"},
                      SceneCase{true, 2, 4, "map_bounce2_spp4_first_hits", 1.0f, K_AUX_PATH_FIRST_HIT},
                      SceneCase{true, 1, 1, "map_sparse4", 2.0f, K_AUX_PATH_FIRST_HIT, 4u},
                      SceneCase{true, 1, 2, "map_every_light", 2.0f, 0u, 0u, K_LIGHTS_EVERY}),
    [](const auto& info) { return std::string(info.param.name); });

// Next-event estimation's shadow rays on a floor of 96 (or 6) lights and an emissive panel, two samples,
// two bounces, soft shadows, the firefly clamp: gather choosing among more lights than its budget, two light
// samples averaged with the shadow roulette, `every` with 6 lights (7 rays a vertex: the shadow walk) and
// with 96 (more than a vertex's slots: the shading kernels walk them); with the shadow walk and without.
class OpenCLWavefrontShadows : public ::testing::TestWithParam<ShadowWalkCase> {};

TEST_P(OpenCLWavefrontShadows, DrawTheMegakernelsImage) {
  if (!tracer_runs_here("opencl")) GTEST_SKIP() << "no OpenCL device here";
  const ShadowWalkCase c = GetParam();
  const int w = 32, h = 24;
  const View view = many_lights_view(c.point_lights, c.projected_lights, w, h);
  ASSERT_EQ(view.scene->emissive_triangles.size(), 2u) << "the panel's triangles are emitters to sample";
  const KFrameParams params = shadow_walk_params(c, h);
  for (const Variant& v : {kWavefront, kShadowsInTheShadingKernels})
    expect_the_megakernels_frame(v, view, params, {0, 11, h}, c.name);
}

INSTANTIATE_TEST_SUITE_P(LightSampling, OpenCLWavefrontShadows, ::testing::ValuesIn(shadow_walk_cases()),
                         [](const auto& info) { return std::string(info.param.name); });

// A band that grows between frames grows the wavefront's scratch (a second, taller band on the same
// tracer), and frames the wavefront does not render (no bounce, a debug view) take the megakernel.
TEST(OpenCLWavefrontScratch, GrowsWithTheBandAndSitsOutFramesWithoutABounce) {
  if (!tracer_runs_here("opencl")) GTEST_SKIP() << "no OpenCL device here";
  const int w = 24, h = 40;
  const View view = room_view(w, h);
  auto mega = opencl(kMegakernel);
  auto wave = opencl(kWavefront);
  mega->apply(commit::CommitBuffer::full(view.scene, 1));
  wave->apply(commit::CommitBuffer::full(view.scene, 1));
  struct Frame {
    uint32_t mode, bounces;
    int begin, end;
  };
  for (const Frame& f : {Frame{K_MODE_PATH, 1, 30, 38}, Frame{K_MODE_PATH, 2, 3, 40}, Frame{K_MODE_PATH, 0, 0, 40},
                         Frame{K_MODE_ALBEDO, 1, 0, 40}, Frame{K_MODE_PATH, 1, 0, 24}}) {
    SCOPED_TRACE("mode " + std::to_string(f.mode) + ", " + std::to_string(f.bounces) + " bounces, rows " +
                 std::to_string(f.begin) + "-" + std::to_string(f.end));
    KFrameParams params = frame_params(f.mode, 1, f.bounces, h);
    params.row_begin = kuint(f.begin);
    params.row_end = kuint(f.end);
    core::BandBuffer a(w, h, core::BandFormat::rgba32f), b(w, h, core::BandFormat::rgba32f);
    core::BandJob job;
    job.params = params;
    job.camera = view.camera;
    const core::BandResult ra = mega->render_band(job, a);
    const core::BandResult rb = wave->render_band(job, b);
    EXPECT_EQ(differing_floats(a, b), 0u);
    EXPECT_EQ(ra.row_work, rb.row_work);
  }
}

// A band tells its own clock, as a CUDA band does (the frame timeline's kernels and transfer spans): the
// device time of its kernels, and its way back (packing to half floats where the target takes them, the
// read), from the queue's profiling; both within the band's wall time. With the transfer queues too, where
// the reads wait on the band's last kernel from a queue of their own.
TEST(OpenCLBandClock, ReportsItsKernelsAndItsWayBack) {
  if (!tracer_runs_here("opencl")) GTEST_SKIP() << "no OpenCL device here";
  const int w = 32, h = 24;
  const View view = room_view(w, h);
  Variant megakernel_transfer = kMegakernel, wavefront_transfer = kWavefront;
  megakernel_transfer.transfer = wavefront_transfer.transfer = tracers::OpenCLTracer::Options::TransferQueue::always;
  megakernel_transfer.name = "megakernel, transfer queues";
  wavefront_transfer.name = "wavefront, transfer queues";
  for (const Variant& v : {kMegakernel, kWavefront, megakernel_transfer, wavefront_transfer}) {
    auto tracer = opencl(v);
    if (v.transfer == tracers::OpenCLTracer::Options::TransferQueue::always) {
      EXPECT_TRUE(tracer->transfer_queues());
    }
    tracer->apply(commit::CommitBuffer::full(view.scene, 1));
    for (const core::BandFormat format : {core::BandFormat::rgb16f, core::BandFormat::rgb9e5, core::BandFormat::rgba32f}) {
      SCOPED_TRACE(std::string(v.name) + ", " + core::to_string(format));
      core::BandBuffer target(w, h, format);
      core::BandJob job;
      job.params = frame_params(K_MODE_PATH, 1, 1, h);
      job.camera = view.camera;
      const auto start = std::chrono::steady_clock::now();
      const core::BandResult result = tracer->render_band(job, target);
      const double wall = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
      EXPECT_GT(result.device_ms, 0.0);
      EXPECT_GT(result.transfer_ms, 0.0);
      EXPECT_LE(result.device_ms + result.transfer_ms, wall);
    }
  }
}

// The switches read from the environment (tracer registry): the wavefront on GPU devices unless
// COHORT_OPENCL_WAVEFRONT says 1 (always) or 0 (never), its shadow walk unless COHORT_OPENCL_SHADOW_WALK=0;
// the register caps counts; a bad value is named.
TEST(OpenCLWavefrontSwitches, TheEnvironmentSetsThemAndABadValueIsNamed) {
  if (!tracer_runs_here("opencl")) GTEST_SKIP() << "no OpenCL device here";
  auto made = [] {
    auto tracer = make_test_tracer("opencl");
    auto* cl = dynamic_cast<tracers::OpenCLTracer*>(tracer.get());
    EXPECT_NE(cl, nullptr);
    return std::make_pair(cl && cl->wavefront(), cl && cl->shadow_walk());
  };
  const auto on_its_own = made();
  EXPECT_EQ(on_its_own.first, make_test_tracer("opencl")->renders_on_gpu()) << "the wavefront on GPUs only";
  EXPECT_TRUE(on_its_own.second);
  // The transfer queues (bands back to back on the device): on GPUs only unless told.
  auto transfer_queues = [] {
    auto tracer = make_test_tracer("opencl");
    auto* cl = dynamic_cast<tracers::OpenCLTracer*>(tracer.get());
    return cl && cl->transfer_queues();
  };
  EXPECT_EQ(transfer_queues(), make_test_tracer("opencl")->renders_on_gpu());
  ::setenv("COHORT_OPENCL_TRANSFER_QUEUE", "1", 1);
  EXPECT_TRUE(transfer_queues());
  ::setenv("COHORT_OPENCL_TRANSFER_QUEUE", "0", 1);
  EXPECT_FALSE(transfer_queues());
  ::unsetenv("COHORT_OPENCL_TRANSFER_QUEUE");
  ::setenv("COHORT_OPENCL_WAVEFRONT", "1", 1);
  EXPECT_EQ(made(), std::make_pair(true, true));
  ::setenv("COHORT_OPENCL_WAVEFRONT", "0", 1);
  ::setenv("COHORT_OPENCL_SHADOW_WALK", "0", 1);
  EXPECT_EQ(made(), std::make_pair(false, false));
  ::unsetenv("COHORT_OPENCL_WAVEFRONT");
  ::unsetenv("COHORT_OPENCL_SHADOW_WALK");
  const std::pair<const char*, const char*> bad_values[] = {{"COHORT_OPENCL_WAVEFRONT", "no"},
                                                            {"COHORT_OPENCL_SHADOW_WALK", "2"},
                                                            {"COHORT_OPENCL_WALK_REGISTERS", "64k"},
                                                            {"COHORT_OPENCL_WALK_REGISTERS", "-1"},
                                                            {"COHORT_OPENCL_SHADE_REGISTERS", "256"},
                                                            {"COHORT_OPENCL_WAVE_LANES", "2"},
                                                            {"COHORT_OPENCL_TRANSFER_QUEUE", "yes"}};
  for (const auto& [variable, bad] : bad_values) {
    const std::string message = registry_error_with(variable, bad, "opencl:0");
    EXPECT_NE(message.find(std::string(variable) + "='" + bad + "'"), std::string::npos) << bad << ": " << message;
  }
}

}  // namespace

#else

TEST(OpenCLWavefront, NeedsOpenCL) { GTEST_SKIP() << "built without OpenCL (COHORT_WITH_OPENCL=OFF)"; }

#endif
