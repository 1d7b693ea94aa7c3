// Two frames in flight on real tracers (Embree, and OpenCL where it runs: PoCL here): over the test map
// with its animated materials (commits every frame) and a turning camera, the frames the pipeline delivers
// are the frames it delivers with one in flight, bit for bit where the band split is the same (the even
// split of `none`) or where one integrator draws both sides of the border (two Embree tracers), else within
// the agreement bound. With two in flight the OpenCL tracer enqueues each band while the one before renders
// (Tracer::enqueues_ahead): the frames must be the same bits, and the tests check that it did.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <functional>
#include <string>
#include <thread>

#include "cohort/core/frame_pipeline.h"
#include "cohort/core/renderer.h"
#include "cohort/core/view.h"
#include "cohort/core/world_sync.h"
#include "cohort/scene/map_loader.h"
#include "cohort/scene/md5.h"
#include "cohort/scene/render_world.h"
#include "test_scenes.h"
#include "test_tracers.h"

#ifdef COHORT_HAVE_OPENCL
#include "cohort/tracers/opencl_tracer.h"
#endif
#ifdef COHORT_HAVE_CUDA
#include "cohort/tracers/cuda_tracer.h"
#endif

using namespace cohort;
using namespace cohort::test;

namespace {

constexpr int kWidth = 64, kHeight = 40, kFrames = 8;

struct Rendered {
  std::vector<core::FrameBuffer> images;
  std::vector<core::GBuffer> planes;  // with aux outputs
  std::vector<core::FrameStats> stats;
  // Summed over the OpenCL tracers: bands enqueued ahead, and those their job then found enqueued.
  size_t enqueued_ahead = 0, finished_ahead = 0, dropped_ahead = 0;
  // Those of the bands enqueued ahead whose kernels were queued straight behind the band before's, its reads
  // on the read queue (OpenCLTracer::bands_back_to_back); and whether every OpenCL tracer had the transfer
  // queues on.
  size_t back_to_back = 0;
  bool transfer_queues = true;
  // Bands whose colour came through page-locked staging (OpenCLTracer::bands_read_through_staging).
  size_t staged_reads = 0;
  // The same counts summed over the CUDA tracers (CudaTracer::bands_enqueued_ahead, ...).
  size_t cuda_enqueued_ahead = 0, cuda_finished_ahead = 0, cuda_dropped_ahead = 0;
  // Bands let start at the band before's release point (CudaTracer::bands_overlapping).
  size_t cuda_overlapping = 0;
};

#ifdef COHORT_HAVE_OPENCL
// Counts what the OpenCL tracer enqueued ahead (OpenCLTracer::bands_enqueued_ahead, _finished_ahead).
void count_ahead(const std::vector<core::Tracer*>& tracers, Rendered& out) {
  for (core::Tracer* t : tracers)
    if (const auto* opencl = dynamic_cast<const tracers::OpenCLTracer*>(t)) {
      out.enqueued_ahead += opencl->bands_enqueued_ahead();
      out.finished_ahead += opencl->bands_finished_ahead();
      out.dropped_ahead += opencl->bands_dropped_ahead();
      out.back_to_back += opencl->bands_back_to_back();
      out.staged_reads += opencl->bands_read_through_staging();
      out.transfer_queues = out.transfer_queues && opencl->transfer_queues();
    }
}
#else
void count_ahead(const std::vector<core::Tracer*>&, Rendered&) {}
#endif

// Counts what the CUDA tracers enqueued ahead.
void count_cuda_ahead([[maybe_unused]] const std::vector<core::Tracer*>& tracers, [[maybe_unused]] Rendered& out) {
#ifdef COHORT_HAVE_CUDA
  for (core::Tracer* t : tracers)
    if (const auto* cuda = dynamic_cast<const tracers::CudaTracer*>(t)) {
      out.cuda_enqueued_ahead += cuda->bands_enqueued_ahead();
      out.cuda_finished_ahead += cuda->bands_finished_ahead();
      out.cuda_dropped_ahead += cuda->bands_dropped_ahead();
      out.cuda_overlapping += cuda->bands_overlapping();
    }
#endif
}

using MakeTracer = std::function<std::unique_ptr<core::Tracer>(const std::string&)>;

#ifdef COHORT_HAVE_OPENCL
// The OpenCL tracer's options here: its bands back to back on the device with the transfer queues, which a
// CPU device (PoCL) leaves off by default (OpenCLTracer::Options::transfer_queue).
tracers::OpenCLTracer::Options opencl_options() {
  tracers::OpenCLTracer::Options o;
  o.device = test_opencl_device();
  o.transfer_queue = tracers::OpenCLTracer::Options::TransferQueue::always;
  return o;
}
std::unique_ptr<core::Tracer> make_sequence_tracer(const std::string& name) {
  if (name != "opencl") return make_test_tracer(name);
  return std::make_unique<tracers::OpenCLTracer>(opencl_options());
}
#else
std::unique_ptr<core::Tracer> make_sequence_tracer(const std::string& name) { return make_test_tracer(name); }
#endif

struct Extras {
  bool move_walker = false;  // the walker posed and moved every frame (skins, instances, the TLAS in every commit)
  kuint aux = 0;             // KFrameParams::aux_outputs
  MakeTracer make = make_sequence_tracer;
  std::chrono::milliseconds frame_timeout{120000};
  core::BandFormat band_format = core::BandFormat::rgba32f;
};

// kFrames of the test map's hall, each frame a little later (its materials change: commits every frame)
// and the camera a little further round, through the pipeline as `cohort render` drives it.
Rendered render_sequence(const std::vector<std::string>& tracer_names, const std::string& balancer, int in_flight,
                         const Extras& extras = {}) {
  const bool move_walker = extras.move_walker;
  const MakeTracer& make = extras.make;
  const std::chrono::milliseconds frame_timeout = extras.frame_timeout;
  scene::Scene map = load_test_map();
  scene::RenderWorld world(map);
  const int walker = world.FindEntityDef("walker_1");
  EXPECT_GE(walker, 0);
  const scene::RenderEntity walker_start = walker >= 0 ? *world.EntityDef(walker) : scene::RenderEntity{};
  core::WorldSyncOptions sync_options;
  sync_options.width = kWidth, sync_options.height = kHeight;
  core::WorldSync sync(world, sync_options);
  world.TakeChanges();
  std::vector<std::unique_ptr<core::Tracer>> tracers;
  for (const std::string& name : tracer_names) tracers.push_back(make(name));
  std::vector<core::Tracer*> made;
  for (const auto& t : tracers) made.push_back(t.get());
  core::RendererOptions options;
  options.balancer = balancer;
  options.frames_in_flight = in_flight;
  options.frame_timeout = frame_timeout;
  options.band_format = extras.band_format;
  core::Renderer renderer(std::move(tracers), options);
  renderer.submit_commit(commit::CommitBuffer::full(sync.snapshot(), 0));
  core::FramePipeline pipeline(renderer);
  Rendered out;
  auto take = [&](std::optional<core::FramePipeline::Delivered> done) {
    if (!done) return;
    out.images.push_back(pipeline.image());
    if (extras.aux) out.planes.push_back(pipeline.gbuffer());
    out.stats.push_back(std::move(done->stats));
  };
  // Frame f's preparation, as `cohort render` does it: its world sync (commits submitted) and its job.
  auto prepare = [&](int f) {
    if (f > 0) {
      sync.set_time(0.3 * f);
      if (move_walker && walker >= 0 && map.entities[size_t(walker)].anim) {
        scene::RenderEntity def = walker_start;
        def.joints = scene::anim_pose(*map.entities[size_t(walker)].anim, 100 * f);
        def.origin += walker_start.axis[0] * (4.0f * float(f));
        world.UpdateEntityDef(walker, def);
      }
      const commit::CommitBuffer records = sync.sync(world.TakeChanges(), uint64_t(f));
      EXPECT_FALSE(records.empty()) << "frame " << f << ": the materials change every frame";
      if (move_walker) {
        EXPECT_FALSE(records.skin_joints().empty()) << "frame " << f << ": the walker should move";
      }
      renderer.submit_commit(records, [&] { return sync.snapshot(); });
    }
    core::BandJob job;
    job.camera = core::make_camera({300, 192, 80}, {180.0f + 4.0f * float(f), 0.0f}, 90.0f, kWidth, kHeight);
    job.params = testmap_agreement_params(kHeight);
    job.params.spp = 2;
    job.params.frame_index = static_cast<kuint>(f);
    job.params.aux_outputs = extras.aux;
    if (f > 0) job.previous_camera = core::make_camera({300, 192, 80}, {180.0f + 4.0f * float(f - 1), 0.0f}, 90.0f, kWidth, kHeight);
    return job;
  };
  // The next frame prepared as soon as one is handed out (push with prepare_next), and with two in flight
  // handed out once the frame before is merged, as `cohort render` does.
  std::optional<core::BandJob> next = prepare(0);
  for (int f = 0; next; ++f) {
    const core::BandJob job = *next;
    next.reset();
    take(pipeline.push(job, {}, [&, f]() -> std::optional<core::BandJob> {
      if (f + 1 < kFrames) next = prepare(f + 1);
      return next;
    }));
  }
  take(pipeline.drain());
  count_ahead(made, out);
  count_cuda_ahead(made, out);
  return out;
}

void expect_same_frames(const Rendered& one, const Rendered& two, bool bit_for_bit, const std::string& label) {
  ASSERT_EQ(one.images.size(), size_t(kFrames)) << label;
  ASSERT_EQ(two.images.size(), size_t(kFrames)) << label;
  for (int f = 0; f < kFrames; ++f) {
    EXPECT_EQ(two.stats[f].frame, uint64_t(f)) << label;
    const core::FrameBuffer& a = one.images[f];
    const core::FrameBuffer& b = two.images[f];
    double mean = 0.0;
    const double error = rgb_rmse(a, b, &mean);
    EXPECT_GT(mean, 0.01) << label << " frame " << f;
    if (bit_for_bit) {
      EXPECT_EQ(error, 0.0) << label << " frame " << f << ": one pixel or more differ";
    } else {
      EXPECT_LT(error, 0.005 * mean) << label << " frame " << f;
    }
    if (f > 0) {
      double unused = 0.0;
      EXPECT_GT(rgb_rmse(a, one.images[f - 1], &unused), 0.0) << label << ": the sequence should move";
    }
  }
}

}  // namespace

TEST(FramesInFlightAgreement, TwoEmbreeTracersDrawTheSameFramesWithTwoInFlightWhereverTheBorderGoes) {
  if (!tracer_runs_here("embree")) GTEST_SKIP() << "needs the Embree tracer";
  // Every pixel from the same integrator: which Embree tracer drew it does not matter, so the border that
  // Robin Hood moves every frame, divided one frame later with two in flight, changes nothing.
  const Rendered one = render_sequence({"embree", "embree"}, "robin-hood", 1);
  const Rendered two = render_sequence({"embree", "embree"}, "robin-hood", 2);
  expect_same_frames(one, two, true, "embree,embree");
  int moved = 0;
  for (int f = 0; f < kFrames; ++f) moved += one.stats[f].tracers[0].row_end != two.stats[f].tracers[0].row_end;
  EXPECT_GT(moved, 0) << "the border should sit elsewhere in some frame with two in flight, or nothing was tested";
}

// With two in flight the OpenCL tracer enqueued bands while the band before rendered (their commit applied
// ahead), and each band's job found it enqueued; with one in flight, none. Not every band: one that ends
// before the core has handed the next frame out (it turns the frame before around meanwhile) has nothing to
// enqueue; on this loaded 2-core VM 5 to 7 of 8 a tracer go ahead.
void expect_enqueued_ahead(const Rendered& one, const Rendered& two, size_t opencl_tracers, const std::string& label) {
  EXPECT_EQ(one.enqueued_ahead, 0u) << label << ": one frame in flight has no next job to enqueue";
  EXPECT_GE(two.finished_ahead, opencl_tracers * 2) << label << ": bands were not enqueued ahead";
  EXPECT_EQ(two.finished_ahead, two.enqueued_ahead) << label << ": a band enqueued ahead was not taken by its job";
  // Each of them back to back on the device: its uploads on the upload queue, the band before's reads on the
  // read queue.
  EXPECT_TRUE(two.transfer_queues) << label << ": the transfer queues are off";
  EXPECT_EQ(two.back_to_back, two.enqueued_ahead) << label << ": a band enqueued ahead was not back to back";
}

TEST(FramesInFlightAgreement, EmbreeAndOpenCLDrawTheSameFramesWithTwoInFlight) {
  if (!tracer_runs_here("embree") || !tracer_runs_here("opencl")) GTEST_SKIP() << "needs the Embree and OpenCL tracers";
  // The even split: the same rows on the same tracer either way, so the same bits; with two in flight the
  // OpenCL bands were enqueued ahead.
  const Rendered one = render_sequence({"embree", "opencl"}, "none", 1), two = render_sequence({"embree", "opencl"}, "none", 2);
  expect_same_frames(one, two, true, "embree,opencl even split");
  expect_enqueued_ahead(one, two, 1, "embree,opencl even split");
  // Rows divided by measured costs move between the two tracers differently: the agreement bound.
  const Rendered balanced_one = render_sequence({"embree", "opencl"}, "perfect-smooth", 1);
  const Rendered balanced_two = render_sequence({"embree", "opencl"}, "perfect-smooth", 2);
  expect_same_frames(balanced_one, balanced_two, false, "embree,opencl balanced");
  expect_enqueued_ahead(balanced_one, balanced_two, 1, "embree,opencl balanced");
}

TEST(FramesInFlightAgreement, OpenCLAloneDrawsTheSameFramesWithTwoInFlightWithAMovingWalker) {
  if (!tracer_runs_here("opencl")) GTEST_SKIP() << "needs the OpenCL tracer";
  // Every commit (materials, the walker's pose, its instance and the TLAS) applied ahead while the band
  // before is still in the queue: the same bits as applied before each band.
  const Rendered one = render_sequence({"opencl"}, "none", 1, {true}), two = render_sequence({"opencl"}, "none", 2, {true});
  expect_same_frames(one, two, true, "opencl, moving walker");
  expect_enqueued_ahead(one, two, 1, "opencl, moving walker");
  // Switched off (COHORT_OPENCL_ENQUEUE_AHEAD=0), the same frames and nothing ahead.
#ifdef COHORT_HAVE_OPENCL
  Extras off_extras;
  off_extras.move_walker = true;
  off_extras.make = [](const std::string&) -> std::unique_ptr<core::Tracer> {
    tracers::OpenCLTracer::Options o = opencl_options();
    o.enqueue_ahead = false;
    return std::make_unique<tracers::OpenCLTracer>(o);
  };
  const Rendered off = render_sequence({"opencl"}, "none", 2, off_extras);
  expect_same_frames(one, off, true, "opencl, enqueue ahead off");
  EXPECT_EQ(off.enqueued_ahead, 0u);
#endif
}

TEST(FramesInFlightAgreement, TwoOpenCLTracersDrawTheSameFramesWithTwoInFlightWithAMovingWalker) {
  if (!tracer_runs_here("opencl")) GTEST_SKIP() << "needs the OpenCL tracer";
  const Rendered one = render_sequence({"opencl", "opencl"}, "none", 1, {true});
  const Rendered two = render_sequence({"opencl", "opencl"}, "none", 2, {true});
  expect_same_frames(one, two, true, "opencl,opencl, moving walker");
  expect_enqueued_ahead(one, two, 2, "opencl,opencl, moving walker");
}

TEST(FramesInFlightAgreement, OpenCLWithCentreRayAuxPlanesDrawsTheSameFramesAndPlanesWithTwoInFlight) {
  if (!tracer_runs_here("opencl")) GTEST_SKIP() << "needs the OpenCL tracer";
  // The aux planes from centre rays (the apps' choice where OpenCL renders) go ahead too: their kernel, the
  // texels' read into page-locked staging and the host copy out of it; the motion vectors read the previous
  // frame's transforms and joints, which the next commit, applied ahead, replaces.
  Extras extras;
  extras.move_walker = true;
  extras.aux = K_AUX_CENTRE_RAY;
  const Rendered one = render_sequence({"opencl", "opencl"}, "none", 1, extras);
  const Rendered two = render_sequence({"opencl", "opencl"}, "none", 2, extras);
  expect_same_frames(one, two, true, "opencl,opencl, centre-ray aux");
  expect_enqueued_ahead(one, two, 2, "opencl,opencl, centre-ray aux");
  ASSERT_EQ(one.planes.size(), size_t(kFrames));
  ASSERT_EQ(two.planes.size(), size_t(kFrames));
  int moving = 0;
  for (int f = 0; f < kFrames; ++f) {
    const core::GBuffer& a = one.planes[f];
    const core::GBuffer& b = two.planes[f];
    ASSERT_FALSE(a.empty());
    EXPECT_EQ(a.depth, b.depth) << "frame " << f;
    EXPECT_EQ(a.prev_depth, b.prev_depth) << "frame " << f;
    EXPECT_EQ(a.motion, b.motion) << "frame " << f;
    EXPECT_EQ(a.normal, b.normal) << "frame " << f;
    EXPECT_EQ(a.albedo, b.albedo) << "frame " << f;
    EXPECT_EQ(a.id, b.id) << "frame " << f;
    moving += std::any_of(a.motion.begin(), a.motion.end(), [](float m) { return m != 0.0f; });
  }
  EXPECT_GT(moving, kFrames / 2) << "the camera turns: motion vectors should not all be 0";
}

// With two in flight each CUDA tracer enqueues its next band while the band before renders (CudaTracer's
// enqueue ahead), the next commit applied first: materials every frame, the walker posed on the GPU, its
// instance and the TLAS. Two CUDA tracers on the first GPU, each band's rows the same either way (the even
// split): the same bits as with one in flight, in float bands, in packed RGB9E5 bands and with the aux
// planes from centre rays and from the paths' first hits (whose texels of the band before may still be
// going down when the next band's kernel writes its own); and the bands were enqueued ahead and taken by
// their jobs. With the materials' commits alone (the walker still), each slot's own arrays take them and the
// next band starts at the band before's release point (with aux planes too: their inputs and outputs are the
// slot's) (CudaTracer::set_band_overlap), by default and with
// every kernel of the next band free to run beside the band before: still the same bits. Switched off
// (COHORT_CUDA_ENQUEUE_AHEAD=0), nothing goes ahead.
TEST(FramesInFlightAgreement, CudaDrawsTheSameFramesWithItsBandsEnqueuedAhead) {
  if (!tracer_runs_here("cuda")) GTEST_SKIP() << "needs a CUDA GPU";
  struct Case {
    const char* label;
    kuint aux;
    core::BandFormat format;
    bool move_walker;
    int overlap;  // CudaTracer::set_band_overlap; -1: the default
  };
  for (const Case& c : {Case{"float bands", 0u, core::BandFormat::rgba32f, true, -1},
                        Case{"RGB9E5 bands", 0u, core::BandFormat::rgb9e5, true, -1},
                        Case{"centre-ray aux planes", kuint(K_AUX_CENTRE_RAY), core::BandFormat::rgba32f, true, -1},
                        Case{"first-hit aux planes", kuint(K_AUX_PATH_FIRST_HIT), core::BandFormat::rgb9e5, true, -1},
                        Case{"materials' commits only", 0u, core::BandFormat::rgb9e5, false, -1},
                        Case{"centre-ray aux planes, materials' commits only", kuint(K_AUX_CENTRE_RAY),
                             core::BandFormat::rgba32f, false, -1},
                        Case{"first-hit aux planes, materials' commits only", kuint(K_AUX_PATH_FIRST_HIT),
                             core::BandFormat::rgb9e5, false, -1},
                        Case{"materials' commits only, whole bands overlapping", 0u, core::BandFormat::rgba32f, false,
                             64}}) {
    Extras extras;
    extras.move_walker = c.move_walker;
    extras.aux = c.aux;
    extras.band_format = c.format;
#ifdef COHORT_HAVE_CUDA
    if (c.overlap >= 0)
      extras.make = [overlap = c.overlap](const std::string& name) -> std::unique_ptr<core::Tracer> {
        auto tracer = make_test_tracer(name);
        if (auto* cuda = dynamic_cast<tracers::CudaTracer*>(tracer.get())) cuda->set_band_overlap(overlap);
        return tracer;
      };
#endif
    const Rendered one = render_sequence({"cuda", "cuda"}, "none", 1, extras);
    const Rendered two = render_sequence({"cuda", "cuda"}, "none", 2, extras);
    expect_same_frames(one, two, true, std::string("cuda,cuda, ") + c.label);
    EXPECT_EQ(one.cuda_enqueued_ahead, 0u) << c.label << ": one frame in flight has no next job to enqueue";
    EXPECT_GE(two.cuda_finished_ahead, 4u) << c.label << ": bands were not enqueued ahead";
    EXPECT_EQ(two.cuda_finished_ahead, two.cuda_enqueued_ahead) << c.label << ": a band enqueued ahead was not taken";
    EXPECT_EQ(two.cuda_dropped_ahead, 0u) << c.label;
    if (!c.move_walker) {
      EXPECT_GE(two.cuda_overlapping, 4u) << c.label << ": bands should start at the band before's release point";
    }
    if (c.aux) {
      ASSERT_EQ(two.planes.size(), size_t(kFrames));
      for (int f = 0; f < kFrames; ++f) {
        EXPECT_EQ(one.planes[f].depth, two.planes[f].depth) << c.label << ", frame " << f;
        EXPECT_EQ(one.planes[f].motion, two.planes[f].motion) << c.label << ", frame " << f;
        EXPECT_EQ(one.planes[f].normal, two.planes[f].normal) << c.label << ", frame " << f;
        EXPECT_EQ(one.planes[f].id, two.planes[f].id) << c.label << ", frame " << f;
      }
    }
  }
#ifdef COHORT_HAVE_CUDA
  Extras off;
  off.move_walker = true;
  off.make = [](const std::string& name) -> std::unique_ptr<core::Tracer> {
    auto tracer = make_test_tracer(name);
    if (auto* cuda = dynamic_cast<tracers::CudaTracer*>(tracer.get())) cuda->set_enqueue_ahead(false);
    return tracer;
  };
  const Rendered without = render_sequence({"cuda", "cuda"}, "none", 2, off);
  const Rendered one = render_sequence({"cuda", "cuda"}, "none", 1, Extras{true});
  expect_same_frames(one, without, true, "cuda,cuda, enqueue ahead off");
  EXPECT_EQ(without.cuda_enqueued_ahead, 0u);
#endif
}

#ifdef COHORT_HAVE_OPENCL
// What an OpenCL tracer enqueued ahead, finished and dropped, as it is destroyed (after its last job).
struct AheadCounts {
  size_t enqueued = 0, finished = 0, dropped = 0, back_to_back = 0;
  bool faulted_with_next_enqueued = false;  // the next band was enqueued ahead inside the faulty one
  bool destroyed = false;
};

// The OpenCL tracer failing on one frame after its band (and the next one, enqueued ahead inside it) is in
// the queue: throwing, or returning only after `stall`, past the frame's timeout.
class FaultyOpenCL final : public tracers::OpenCLTracer {
 public:
  FaultyOpenCL(const Options& options, kuint fault_frame, std::chrono::milliseconds stall,
               std::shared_ptr<AheadCounts> counts)
      : tracers::OpenCLTracer(options), fault_frame_(fault_frame), stall_(stall), counts_(std::move(counts)) {}
  ~FaultyOpenCL() override {
    *counts_ = {bands_enqueued_ahead(), bands_finished_ahead(), bands_dropped_ahead(), bands_back_to_back(),
                faulted_with_next_enqueued_, true};
  }
  using core::Tracer::render_band;
  core::BandResult render_band(const core::BandJob& job, core::BandBuffer& target) override {
    const bool fault = job.params.frame_index == fault_frame_;
    // Long enough for the core to hand the next frame out (it does not wait for this band to do so): the
    // band then enqueues its successor ahead, whatever the load on this machine.
    if (fault) std::this_thread::sleep_for(std::chrono::milliseconds(300));
    const size_t ahead_before = bands_enqueued_ahead();
    core::BandResult result = tracers::OpenCLTracer::render_band(job, target);
    if (!fault) return result;
    faulted_with_next_enqueued_ = bands_enqueued_ahead() > ahead_before;
    if (stall_.count() == 0) throw std::runtime_error("injected fault after the band");
    std::this_thread::sleep_for(stall_);
    return result;
  }

 private:
  kuint fault_frame_;
  std::chrono::milliseconds stall_;
  std::shared_ptr<AheadCounts> counts_;
  bool faulted_with_next_enqueued_ = false;
};

// stall: 0 for a throw. A stall of 3 s outlasts the sequence: the Renderer shuts down while the band stalls,
// and drops the next job, whose band the tracer enqueued ahead: it drains it (the shutdown waits up to 2 s).
void expect_fault_recovered(std::chrono::milliseconds stall_time) {
  const bool stall = stall_time.count() > 0;
  const bool outlasts = stall_time >= std::chrono::seconds(2);
  if (!tracer_runs_here("embree") || !tracer_runs_here("opencl")) GTEST_SKIP() << "needs the Embree and OpenCL tracers";
  constexpr kuint kFaultFrame = 3;
  bool made = false;
  auto counts = std::make_shared<AheadCounts>();
  const MakeTracer make = [&](const std::string& name) -> std::unique_ptr<core::Tracer> {
    if (name != "opencl") return make_test_tracer(name);
    auto t = std::make_unique<FaultyOpenCL>(opencl_options(), kFaultFrame, stall_time, counts);
    made = true;
    return t;
  };
  const Rendered reference = render_sequence({"embree", "opencl"}, "none", 1);
  // A PoCL band here takes tens of ms; the timeout 0.8 s.
  Extras extras;
  extras.make = make;
  extras.frame_timeout = std::chrono::milliseconds(800);
  const Rendered faulted = render_sequence({"embree", "opencl"}, "none", 2, extras);
  ASSERT_TRUE(made);
  ASSERT_TRUE(counts->destroyed) << "the stalled tracer outlived the Renderer's shutdown";
  EXPECT_TRUE(counts->faulted_with_next_enqueued) << "the next band should have been enqueued ahead of the fault";
  EXPECT_GT(counts->finished, 0u);
  EXPECT_EQ(counts->enqueued, counts->finished + counts->dropped) << "a band enqueued ahead was neither taken nor drained";
  EXPECT_EQ(counts->back_to_back, counts->enqueued) << "the bands enqueued ahead should have gone back to back";
  EXPECT_EQ(counts->dropped, outlasts ? 1u : 0u) << "the job dropped at shutdown had its band enqueued ahead";
  ASSERT_EQ(faulted.images.size(), size_t(kFrames));
  ASSERT_EQ(faulted.stats.size(), size_t(kFrames));
  const core::TracerOutcome expected = stall ? core::TracerOutcome::timed_out : core::TracerOutcome::threw;
  EXPECT_EQ(faulted.stats[kFaultFrame].tracers[1].outcome, expected);
  // Every frame whole and in order. The rows each tracer rendered in its own band of its own frame are the
  // reference's bits; rows re-rendered after a fault show the frame after's scene (docs/balancing.md, "Two
  // frames in flight"), and a frame one tracer sat out has another split: those are only checked lit.
  for (int f = 0; f < kFrames; ++f) {
    EXPECT_EQ(faulted.stats[f].frame, uint64_t(f));
    const core::FrameBuffer& a = reference.images[f];
    const core::FrameBuffer& b = faulted.images[f];
    for (int y = 0; y < kHeight; ++y) {
      double sum = 0.0;
      for (int x = 0; x < kWidth * 4; ++x) sum += b.row(y)[x];
      EXPECT_GT(sum, 0.0) << "frame " << f << " row " << y << " is black: not delivered whole";
    }
    for (size_t t = 0; t < 2; ++t) {
      const core::TracerFrameStats& mine = faulted.stats[f].tracers[t];
      const core::TracerFrameStats& theirs = reference.stats[f].tracers[t];
      if (mine.outcome != core::TracerOutcome::rendered || mine.row_begin != theirs.row_begin || mine.row_end != theirs.row_end)
        continue;
      for (int y = mine.row_begin; y < mine.row_end; ++y)
        ASSERT_EQ(std::memcmp(a.row(y), b.row(y), sizeof(float) * 4 * kWidth), 0)
            << "frame " << f << " row " << y << " of tracer " << t << "'s own band differs from the reference";
    }
  }
  if (!outlasts) {
    EXPECT_EQ(faulted.stats[kFrames - 1].tracers[1].outcome, core::TracerOutcome::rendered) << "the OpenCL tracer rejoins";
  }
}

TEST(FramesInFlightAgreement, AThrownOpenCLBandWithItsSuccessorEnqueuedAheadIsRecovered) {
  expect_fault_recovered(std::chrono::milliseconds(0));
}
TEST(FramesInFlightAgreement, AStalledOpenCLBandWithItsSuccessorEnqueuedAheadIsRecovered) {
  expect_fault_recovered(std::chrono::milliseconds(700));
}
TEST(FramesInFlightAgreement, ShutdownDuringAStalledOpenCLBandDrainsTheBandEnqueuedAheadForTheDroppedJob) {
  expect_fault_recovered(std::chrono::milliseconds(3000));
}
#endif

#ifdef COHORT_HAVE_OPENCL
// The bands back to back on the device (uploads on the upload queue, reads on the read queue behind the
// band's last kernel, the edges' buffers in two slots; the colour read into page-locked staging or straight
// into the target) against everything on the compute queue: the same bits, frame after frame, with commits
// every frame (the walker posed and moved: skins, instances, the TLAS), an OpenCL band that starts below
// Embree's, the float band and the packed one (RGB9E5, its packing kernel the band's last), the megakernel
// and the wavefront.
TEST(FramesInFlightAgreement, OpenCLBandsBackToBackOnTheDeviceAreTheBandsRenderedWithEverythingOnOneQueue) {
  if (!tracer_runs_here("embree") || !tracer_runs_here("opencl")) GTEST_SKIP() << "needs the Embree and OpenCL tracers";
  struct Case {
    tracers::OpenCLTracer::Options::Wavefront wavefront;
    core::BandFormat format;
    bool pinned_reads;
    const char* label;
  };
  for (const Case& c : {Case{tracers::OpenCLTracer::Options::Wavefront::never, core::BandFormat::rgba32f, true,
                             "megakernel, floats, through staging"},
                        Case{tracers::OpenCLTracer::Options::Wavefront::always, core::BandFormat::rgb9e5, true,
                             "wavefront, RGB9E5, through staging"},
                        Case{tracers::OpenCLTracer::Options::Wavefront::always, core::BandFormat::rgb9e5, false,
                             "wavefront, RGB9E5, straight into the target"}}) {
    auto extras_with = [&](bool transfer_queue) {
      Extras e;
      e.move_walker = true;
      e.band_format = c.format;
      e.make = [&c, transfer_queue](const std::string& name) -> std::unique_ptr<core::Tracer> {
        if (name != "opencl") return make_test_tracer(name);
        tracers::OpenCLTracer::Options o = opencl_options();
        o.wavefront = c.wavefront;
        o.pinned_band_reads = c.pinned_reads;
        o.transfer_queue = transfer_queue ? tracers::OpenCLTracer::Options::TransferQueue::always
                                          : tracers::OpenCLTracer::Options::TransferQueue::never;
        return std::make_unique<tracers::OpenCLTracer>(o);
      };
      return e;
    };
    const Rendered on = render_sequence({"embree", "opencl"}, "none", 2, extras_with(true));
    const Rendered off = render_sequence({"embree", "opencl"}, "none", 2, extras_with(false));
    expect_same_frames(on, off, true, std::string("back to back against one queue, ") + c.label);
    EXPECT_TRUE(on.transfer_queues) << c.label;
    EXPECT_FALSE(off.transfer_queues) << c.label;
    EXPECT_GE(on.back_to_back, 2u) << c.label << ": bands should have gone back to back";
    EXPECT_EQ(on.back_to_back, on.enqueued_ahead) << c.label;
    EXPECT_EQ(off.back_to_back, 0u) << c.label;
    EXPECT_GE(off.finished_ahead, 2u) << c.label << ": without the transfer queues bands still go ahead";
    // Every band of the run (one a frame) through staging, or none: without the transfer queues there is no
    // second slot to keep the next band's read out of the staging being copied.
    EXPECT_EQ(on.staged_reads, c.pinned_reads ? size_t(kFrames) : 0u) << c.label;
    EXPECT_EQ(off.staged_reads, 0u) << c.label;
    ASSERT_EQ(on.stats.size(), size_t(kFrames));
    for (int f = 0; f < kFrames; ++f)
      EXPECT_GT(on.stats[f].tracers[1].row_begin, 0) << c.label << " frame " << f << ": OpenCL's band should start below Embree's";
  }
}

// Where the transfer queues are on: by default on GPU devices only; never without enqueue ahead.
TEST(FramesInFlightAgreement, OpenCLTransferQueuesAreOnByDefaultOnGpusOnlyAndNeedEnqueueAhead) {
  if (!tracer_runs_here("opencl")) GTEST_SKIP() << "needs the OpenCL tracer";
  tracers::OpenCLTracer::Options o = opencl_options();
  o.transfer_queue = tracers::OpenCLTracer::Options::TransferQueue::on_gpus;
  const tracers::OpenCLTracer by_default(o);
  EXPECT_EQ(by_default.transfer_queues(), by_default.renders_on_gpu());
  o.transfer_queue = tracers::OpenCLTracer::Options::TransferQueue::always;
  EXPECT_TRUE(tracers::OpenCLTracer(o).transfer_queues());
  o.enqueue_ahead = false;
  EXPECT_FALSE(tracers::OpenCLTracer(o).transfer_queues());
}
#endif
