// The frame's post-processing (core/frame_post.h) by place: the host composition equals its parts, a
// GPU runs the same portable kernel and must give the host's picture over a moving sequence (history,
// disocclusion, the a-trous passes), and places are named clearly or refused.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <stdexcept>

#include "cohort/core/atrous_filter.h"
#include "cohort/core/convergence.h"
#include "cohort/core/frame_post.h"
#include "cohort/core/reprojection.h"
#include "cohort/core/renderer.h"
#include "cohort/core/upsample.h"
#include "cohort/kernel/path_pattern.h"
#include "cohort/core/gpu_scene.h"
#include "cohort/tracers/tracer_registry.h"
#include "test_scenes.h"
#include "test_tracers.h"

using namespace cohort;

namespace {

constexpr int kW = 96, kH = 64;

// Frame `f` of a scene sliding right by 0.7 pixels a frame: a floor (id 0, depth ramp), a box (id 5) that
// uncovers the floor as it moves, and sky (misses) on the top rows; noisy colours, and one NaN sample.
void make_frame(int f, core::FrameBuffer& frame, core::GBuffer& g) {
  frame.resize(kW, kH);
  g.resize(kW, kH);
  std::mt19937 rng(100 + f);
  std::uniform_real_distribution<float> noise(0.5f, 1.5f);
  const float shift = 0.7f * f;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const size_t p = size_t(y) * kW + x;
      const bool sky = y < 8;
      const bool box = !sky && x - shift > 30 && x - shift < 50 && y > 20 && y < 44;
      g.depth[p] = sky ? 0.0f : box ? 6.0f : 10.0f + 0.05f * y;
      g.prev_depth[p] = g.depth[p];
      g.motion[2 * p] = f == 0 ? 0.0f : -0.7f;
      g.normal[3 * p + (box ? 0 : 2)] = sky ? 0.0f : 1.0f;
      for (int k = 0; k < 3; ++k) g.albedo[3 * p + k] = box ? 0.8f : 0.3f + 0.2f * ((x / 4 + y / 4) % 2);
      g.id[p] = sky ? 0xFFFFFFFFu : box ? 5u : 0u;
      const float light = sky ? 0.2f : box ? 2.0f : 1.0f;
      float* c = frame.rgba.data() + 4 * p;
      for (int k = 0; k < 3; ++k) c[k] = light * g.albedo[3 * p + k] * noise(rng) * (sky ? 5.0f : 1.0f);
      c[3] = 1.0f;
    }
  frame.rgba[4 * (30 * kW + 10)] = std::nanf("");
}

core::FramePostOptions both() {
  core::FramePostOptions o;
  o.reproject = true;
  o.atrous = true;
  o.atrous_options.passes = 2;
  return o;
}

// A still path-traced frame of the test room with its aux planes (the camera its own previous one).
core::BandJob aux_room_job(int w, int h) {
  core::BandJob job;
  job.camera = test::test_room_camera(w, h);
  job.previous_camera = job.camera;
  job.params = test::frame_params(K_MODE_PATH, 1, 1, h);
  job.params.aux_outputs = 1u;
  return job;
}

// Dynamic resolution's frame f: the pixels outside the pattern traced nothing (black, as the tracers leave them).
core::PathPattern sparse_frame(int f, core::FrameBuffer& frame, core::GBuffer& g) {
  make_frame(f, frame, g);
  const core::PathPattern pattern = core::path_pattern_for_scale(0.5, uint64_t(f));
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      if (!k_pixel_traces_path(pattern.pixels, pattern.phase, kuint(x), kuint(y)))
        for (int k = 0; k < 3; ++k) frame.rgba[4 * (size_t(y) * kW + x) + k] = 0.0f;
  return pattern;
}

double max_relative_difference(const core::FrameBuffer& a, const core::FrameBuffer& b) {
  double worst = 0.0;
  for (size_t i = 0; i < a.rgba.size(); ++i)
    worst = std::max(worst, std::fabs(double(a.rgba[i]) - b.rgba[i]) / (std::fabs(double(b.rgba[i])) + 1e-3));
  return worst;
}

// Share of the values whose relative difference (as max_relative_difference weighs it) exceeds `bound`.
double share_beyond(const core::FrameBuffer& a, const core::FrameBuffer& b, double bound) {
  size_t beyond = 0;
  for (size_t i = 0; i < a.rgba.size(); ++i)
    if (std::fabs(double(a.rgba[i]) - b.rgba[i]) / (std::fabs(double(b.rgba[i])) + 1e-3) > bound) ++beyond;
  return a.rgba.empty() ? 0.0 : double(beyond) / double(a.rgba.size());
}

}  // namespace

TEST(FramePost, HostRunsReprojectionThenTheFilter) {
  for (core::AtrousGuide guide :
       {core::AtrousGuide::variance, core::AtrousGuide::variance_of_mean, core::AtrousGuide::fixed}) {
    core::FramePostOptions options = both();
    options.atrous_options.guide = guide;
    core::HostFramePost post(options);
    // The variance guide reads the history's luminance moments, which only it switches on.
    core::ReprojectionOptions reprojection_options;
    reprojection_options.luminance_moments = guide != core::AtrousGuide::fixed;
    EXPECT_EQ(core::with_history_moments(options).reprojection.luminance_moments, reprojection_options.luminance_moments);
    core::TemporalReprojection reprojection(reprojection_options);
    core::AtrousFilter filter(options.atrous_options);
    core::FrameBuffer frame, filtered;
    core::GBuffer g;
    for (int f = 0; f < 5; ++f) {
      make_frame(f, frame, g);
      post.process(frame, g, core::kEveryPixel);
      reprojection.accumulate(frame, g);
      // The history lengths always (the history fix reads them), the moments with the variance guides.
      core::AtrousHistory history{nullptr, reprojection.history_length().data()};
      if (reprojection_options.luminance_moments) history.moments = reprojection.luminance_moments().data();
      filter.apply(reprojection.image(), g, filtered, history);
      ASSERT_EQ(post.image().rgba, filtered.rgba) << "frame " << f << " " << core::atrous_guide_name(guide);
      EXPECT_DOUBLE_EQ(post.mean_history_length(), reprojection.mean_history_length());
    }
    EXPECT_GT(post.mean_history_length(), 2.0) << "the sliding floor keeps its history";
  }
}

TEST(FramePost, HostWithNeitherStepShowsTheFrame) {
  core::FramePostOptions none;
  none.reproject = false;
  core::HostFramePost post(none);
  core::FrameBuffer frame;
  core::GBuffer g;
  make_frame(1, frame, g);
  post.process(frame, g, core::kEveryPixel);
  EXPECT_EQ(post.image().rgba.size(), frame.rgba.size());
  EXPECT_DOUBLE_EQ(post.mean_history_length(), 1.0);
  EXPECT_EQ(post.where(), "host");
}

// A sparse frame is reconstructed where the post runs, before the reprojection: the same picture as the
// reconstruction on the host followed by the post on the full frame.
TEST(FramePost, HostReconstructsSparseFramesBeforeReprojecting) {
  for (core::UpsampleMethod method : {core::UpsampleMethod::joint_bilateral, core::UpsampleMethod::nearest}) {
    core::FramePostOptions options = both();
    options.upsample = method;
    core::HostFramePost post(options), after_host_reconstruction(options);
    core::FrameBuffer frame, full;
    core::GBuffer g;
    for (int f = 0; f < 4; ++f) {
      const core::PathPattern pattern = sparse_frame(f, frame, g);
      ASSERT_TRUE(pattern.sparse());
      post.process(frame, g, pattern);
      core::upsample_sparse(frame, g, pattern, method, full);
      after_host_reconstruction.process(full, g, core::kEveryPixel);
      ASSERT_EQ(post.image().rgba, after_host_reconstruction.image().rgba)
          << "frame " << f << " " << core::upsample_method_name(method);
    }
  }
}

// A post with neither step only reconstructs (Brigade's blend follows it); a filter without history takes
// blended frames, so it refuses a sparse one, and bilinear stretches a small frame, it does not fill a sparse one.
TEST(FramePost, SparseFramesAreReconstructedOrRefused) {
  core::FrameBuffer frame, full;
  core::GBuffer g;
  const core::PathPattern pattern = sparse_frame(1, frame, g);
  core::FramePostOptions neither;
  neither.reproject = false;
  core::HostFramePost reconstruction(neither);
  reconstruction.process(frame, g, pattern);
  core::upsample_sparse(frame, g, pattern, core::UpsampleMethod::joint_bilateral, full);
  EXPECT_EQ(reconstruction.image().rgba, full.rgba);
  core::FramePostOptions filter_only = both();
  filter_only.reproject = false;
  EXPECT_THROW(core::HostFramePost(filter_only).process(frame, g, pattern), std::invalid_argument);
  core::FramePostOptions bilinear = both();
  bilinear.upsample = core::UpsampleMethod::bilinear;
  EXPECT_THROW(core::HostFramePost(bilinear).process(frame, g, pattern), std::invalid_argument);
  EXPECT_NO_THROW(core::HostFramePost(filter_only).process(frame, g, core::kEveryPixel));
}

TEST(FramePost, PlacesAreNamedOrRefused) {
  EXPECT_EQ(tracers::make_frame_post("host", both())->where(), "host");
  EXPECT_THROW(tracers::make_frame_post("gpu", both()), std::invalid_argument);
  EXPECT_THROW(tracers::make_frame_post("cuda:x", both()), std::invalid_argument);
  EXPECT_ANY_THROW(tracers::make_frame_post("cuda:99", both()));  // no such device, or no CUDA in this build
  EXPECT_EQ(tracers::auto_frame_post_place(tracers::parse_tracer_list("embree")), "host");
  core::FramePostOptions odd = both();
  odd.atrous_options.normal_power = 48;
  EXPECT_THROW(tracers::make_frame_post("host", odd)->process(core::FrameBuffer{}, core::GBuffer{}, core::kEveryPixel),
               std::invalid_argument);
}

TEST(FramePost, CudaMatchesTheHostOverAMovingSequence) {
  if (tracers::device_count("cuda") == 0) GTEST_SKIP() << "no CUDA device (or a build without CUDA)";
  EXPECT_EQ(tracers::auto_frame_post_place(tracers::parse_tracer_list("embree,cuda:0")), "cuda:0");
  // No filter, the fixed guide, the variance guide over the history's moments, the variance guide alone
  // (spatial estimate only), the variance of the mean, that with first-hit planes' footprint taps, and the
  // history fix before the variance-of-mean and the fixed guides' passes, and the firefly clamp before them.
  for (int variant = 0; variant < 9; ++variant) {
    const bool atrous = variant > 0;
    core::FramePostOptions options = both();
    options.atrous = atrous;
    options.reproject = variant != 3;
    options.atrous_options.guide = variant == 1 || variant == 7 ? core::AtrousGuide::fixed
                                   : variant >= 4 ? core::AtrousGuide::variance_of_mean
                                                  : core::AtrousGuide::variance;
    // First-hit planes: history taps of another surface in the pixel's footprint (the sliding box's edges).
    options.reprojection.jittered_planes = variant == 5;
    if (variant == 6 || variant == 7) options.atrous_options.history_fix_frames = 4.0f;  // lengths 1-6 along the sequence
    if (variant == 8) options.atrous_options.firefly_factor = 3.0f;
    core::HostFramePost host(options);
    std::unique_ptr<core::FramePost> gpu = tracers::make_frame_post("cuda:0", options);
    EXPECT_EQ(gpu->where(), "cuda:0");
    core::FrameBuffer frame;
    core::GBuffer g;
    for (int f = 0; f < 6; ++f) {
      make_frame(f, frame, g);
      if (variant == 8)  // a firefly for the clamp, somewhere else each frame
        for (int k = 0; k < 3; ++k) frame.rgba[4 * (size_t(5 + f) * kW + 7 + 3 * f) + k] = 60.0f;
      host.process(frame, g, core::kEveryPixel);
      gpu->process(frame, g, core::kEveryPixel);
      ASSERT_EQ(gpu->image().width, kW);
      // Same arithmetic; only the device's exp/sqrt/FMA contraction differ.
      EXPECT_LT(max_relative_difference(gpu->image(), host.image()), 2e-3) << "frame " << f << " variant " << variant;
      EXPECT_NEAR(gpu->mean_history_length(), host.mean_history_length(), 1e-3) << "frame " << f;
      EXPECT_TRUE(gpu->device_times().measured);
      EXPECT_GT(gpu->device_times().passes_ms, 0.0);
      EXPECT_FALSE(host.device_times().measured);
    }
    gpu->reset();
    host.reset();
    make_frame(7, frame, g);
    host.process(frame, g, core::kEveryPixel);
    gpu->process(frame, g, core::kEveryPixel);
    EXPECT_NEAR(gpu->mean_history_length(), 1.0, 1e-3) << "reset drops the history";
    EXPECT_NEAR(host.mean_history_length(), 1.0, 1e-3);
  }
}

// The reconstruction on the GPU (kernel/upsample.h in CUDA) gives the host's picture, from float planes and
// from the packed frame, whose YCoCg planes are then made after the reconstruction.
TEST(FramePost, CudaReconstructsSparseFramesAsTheHost) {
  if (tracers::device_count("cuda") == 0) GTEST_SKIP() << "no CUDA device (or a build without CUDA)";
  for (int variant = 0; variant < 3; ++variant) {
    const core::UpsampleMethod method =
        variant == 1 ? core::UpsampleMethod::nearest : core::UpsampleMethod::joint_bilateral;
    core::FramePostOptions options = both();
    options.upsample = method;
    if (variant == 2) options.reproject = options.atrous = false;  // the reconstruction alone
    core::HostFramePost host(options);
    std::unique_ptr<core::FramePost> gpu = tracers::make_frame_post("cuda:0", options);
    core::FrameBuffer frame;
    core::GBuffer g;
    for (int f = 0; f < 5; ++f) {
      const core::PathPattern pattern = sparse_frame(f, frame, g);
      host.process(frame, g, pattern);
      gpu->process(frame, g, pattern);
      // The sparse frame's hard edges feed the a-trous stops, which can turn the GPU's float rounding (FMA,
      // another order of the variance sums) into up to about 1 % at a single pixel once the reprojection's
      // wide clamp lets the history through (0.8 % seen on an H100): nearly every value agrees within 2e-3,
      // and none is off by more than 2e-2.
      EXPECT_LT(share_beyond(gpu->image(), host.image(), 2e-3), 1e-3) << "frame " << f << " variant " << variant;
      EXPECT_LT(max_relative_difference(gpu->image(), host.image()), 2e-2) << "frame " << f << " variant " << variant;
      EXPECT_NEAR(gpu->mean_history_length(), host.mean_history_length(), 1e-3) << "frame " << f;
    }
  }
}

namespace {

// The Renderer's packed merge (bands copied as the tracers wrote them) holds exactly what the float merge
// makes, and every place's post-processing gives the same picture from it, bands in `format`.
void check_packed_merge(core::BandFormat format) {
  using namespace cohort::test;
  SCOPED_TRACE(core::to_string(format));
  auto room = std::make_shared<commit::TracerScene>(core::compile_scene(test_room()).tracer_scene);
  std::vector<std::unique_ptr<core::Tracer>> list;
  list.push_back(make_test_tracer("embree"));
  list.push_back(make_test_tracer("embree"));
  core::RendererOptions options;
  options.balancer = "none";
  options.band_format = format;
  core::Renderer renderer(std::move(list), options);
  renderer.submit_commit(commit::CommitBuffer::full(room, 1));
  const int w = 48, h = 32;
  const core::BandJob job = aux_room_job(w, h);
  core::FrameBuffer floats;
  renderer.render(job, floats);
  const core::GBuffer g = renderer.gbuffer();
  ASSERT_FALSE(g.empty());
  renderer.set_packed_merge(true);
  core::FrameBuffer untouched;
  renderer.render(job, untouched);
  const core::BandBuffer& packed = renderer.packed_frame();
  ASSERT_TRUE(packed.has_aux());
  core::FrameBuffer unpacked;
  unpacked.resize(w, h);
  packed.copy_rows_to(unpacked, 0, h);
  EXPECT_EQ(unpacked.rgba, floats.rgba);
  core::GBuffer unpacked_g;
  unpacked_g.resize(w, h);
  packed.copy_aux_rows_to(unpacked_g, 0, h);
  EXPECT_EQ(unpacked_g.depth, g.depth);
  EXPECT_EQ(unpacked_g.normal, g.normal);
  EXPECT_EQ(unpacked_g.albedo, g.albedo);
  EXPECT_EQ(unpacked_g.id, g.id);
  EXPECT_EQ(unpacked_g.motion, g.motion);

  core::HostFramePost from_floats(both()), from_packed(both());
  from_floats.process(floats, g, core::kEveryPixel);
  from_packed.process_packed(packed, {}, core::kEveryPixel);
  EXPECT_EQ(from_packed.image().rgba, from_floats.image().rgba);
  std::unique_ptr<core::FramePost> gpu;
  if (tracers::device_count("cuda") > 0) {
    gpu = tracers::make_frame_post("cuda:0", both());
    gpu->process_packed(packed, {}, core::kEveryPixel);
    EXPECT_LT(max_relative_difference(gpu->image(), from_floats.image()), 2e-3) << "packed frame on cuda:0";
  }

  // The next frame traced sparsely (dynamic resolution at scale 0.5): reconstructed inside each post.
  core::BandJob sparse_job = job;
  const core::PathPattern pattern = core::path_pattern_for_scale(0.5, 1);
  sparse_job.params.frame_index = 2;
  sparse_job.params.path_pixels = pattern.pixels;
  sparse_job.params.path_phase = pattern.phase;
  renderer.set_packed_merge(false);
  renderer.render(sparse_job, floats);
  const core::GBuffer sparse_g = renderer.gbuffer();
  renderer.set_packed_merge(true);
  renderer.render(sparse_job, untouched);
  from_floats.process(floats, sparse_g, pattern);
  from_packed.process_packed(renderer.packed_frame(), {}, pattern);
  EXPECT_EQ(from_packed.image().rgba, from_floats.image().rgba) << "sparse frame";
  if (gpu) {
    gpu->process_packed(renderer.packed_frame(), {}, pattern);
    EXPECT_LT(max_relative_difference(gpu->image(), from_floats.image()), 2e-3) << "sparse packed frame on cuda:0";
  }
}

}  // namespace

TEST(FramePost, PackedMergeUnpacksToTheFloatMergeEverywhere) {
  for (core::BandFormat format : {core::BandFormat::rgb16f, core::BandFormat::rgb9e5}) check_packed_merge(format);
}

namespace {

// cuda:0, Embree and cuda:1 where there is one, the rows split evenly, bands in `format`, the test room
// committed.
std::unique_ptr<core::Renderer> gpu_room_renderer(int gpus, core::BandFormat format = core::BandFormat::rgb16f) {
  using namespace cohort::test;
  auto room = std::make_shared<commit::TracerScene>(core::compile_scene(test_room()).tracer_scene);
  std::vector<std::unique_ptr<core::Tracer>> list;
  list.push_back(make_test_tracer("cuda:0"));
  list.push_back(make_test_tracer("embree"));
  if (gpus > 1) list.push_back(make_test_tracer("cuda:1"));
  core::RendererOptions options;
  options.balancer = "none";
  options.band_format = format;
  auto renderer = std::make_unique<core::Renderer>(std::move(list), options);
  renderer->submit_commit(commit::CommitBuffer::full(room, 1));
  return renderer;
}

}  // namespace

// CUDA tracers' bands can stay on their GPUs (Renderer::set_device_bands): the post-processing on cuda:0
// copies them device to device or from the peer GPU, host bands (Embree's rows) come up between them,
// and the picture is the one the bands give through the host.
TEST(FramePost, CudaBandsStayingOnTheGpusGiveTheHostRoundTripsPicture) {
  using namespace cohort::test;
  const int gpus = tracers::device_count("cuda");
  if (gpus == 0) GTEST_SKIP() << "no CUDA device (or a build without CUDA)";
  const int w = 64, h = 48;
  core::BandJob job = aux_room_job(w, h);
  const size_t cuda_bands = gpus > 1 ? 2 : 1;
  for (core::BandFormat format : {core::BandFormat::rgb16f, core::BandFormat::rgb9e5}) {
    SCOPED_TRACE(core::to_string(format));
    std::vector<core::FrameBuffer> shown[2];
    for (int on_device = 0; on_device < 2; ++on_device) {
      std::unique_ptr<core::Renderer> room_renderer = gpu_room_renderer(gpus, format);
      core::Renderer& renderer = *room_renderer;
      std::unique_ptr<core::FramePost> post = tracers::make_frame_post("cuda:0", both());
      ASSERT_EQ(post->cuda_device(), 0);
      renderer.set_packed_merge(true);
      if (on_device) renderer.set_device_bands(post->cuda_device());
      core::FrameBuffer untouched;
      for (int f = 0; f < 3; ++f) {
        job.params.frame_index = static_cast<kuint>(f + 1);
        renderer.render(job, untouched);
        const std::vector<core::DeviceBandRows>& rows = renderer.packed_device_rows();
        EXPECT_EQ(rows.size(), on_device ? cuda_bands : 0u) << "every CUDA band, and only those";
        for (const core::DeviceBandRows& r : rows) EXPECT_LT(r.row_begin, r.row_end);
        post->process_packed(renderer.packed_frame(), rows, core::kEveryPixel);
        shown[on_device].push_back(post->image());
      }
      core::HostFramePost host(both());
      if (on_device) {
        EXPECT_THROW(host.process_packed(renderer.packed_frame(), renderer.packed_device_rows(), core::kEveryPixel), std::invalid_argument);
      }
    }
    for (size_t f = 0; f < shown[0].size(); ++f)
      EXPECT_EQ(shown[1][f].rgba, shown[0][f].rgba) << "frame " << f;
  }
}

// Brigade's blend as a step of the post (FramePostOptions::blend): the host's gives AdaptiveConvergence's
// image bit for bit, a GPU's the same picture from float frames and from a packed merge without aux planes
// whose CUDA bands stayed on their GPUs; it refuses to come with the reprojection or the filter.
namespace {

// A short walk: still for three frames (f = 1, 1/2, 1/3), two steps of 4 units, a cut, still again.
KCamera walk_camera(int f) {
  KCamera c = test::test_room_camera(kW, kH);
  c.origin[0] += f < 3 ? 0.0f : f < 5 ? 4.0f * float(f - 2) : 400.0f;
  return c;
}

bool same_bits(const core::FrameBuffer& a, const core::FrameBuffer& b) {
  return a.rgba.size() == b.rgba.size() &&
         std::memcmp(a.rgba.data(), b.rgba.data(), a.rgba.size() * sizeof(float)) == 0;  // NaN samples too
}

core::FramePostOptions blend_only() {
  core::FramePostOptions o;
  o.reproject = false;
  o.blend = true;
  return o;
}

}  // namespace

TEST(FramePost, HostBlendIsBrigadesConvergence) {
  core::HostFramePost post(blend_only());
  core::AdaptiveConvergence reference, factors;
  core::FrameBuffer frame;
  core::GBuffer g;
  std::vector<double> seen;
  for (int f = 0; f < 7; ++f) {
    make_frame(f, frame, g);
    const KCamera camera = walk_camera(f);
    seen.push_back(factors.next_factor(camera));
    post.set_blend_factor(seen.back());
    post.process(frame, core::GBuffer{}, core::kEveryPixel);  // the blend reads no G-buffer
    EXPECT_DOUBLE_EQ(reference.accumulate(camera, frame), seen.back());
    EXPECT_TRUE(same_bits(post.image(), reference.image())) << "frame " << f;
  }
  EXPECT_DOUBLE_EQ(seen[0], 1.0);
  EXPECT_DOUBLE_EQ(seen[2], 1.0 / 3.0);
  EXPECT_DOUBLE_EQ(seen[5], 1.0) << "the cut starts over";
  EXPECT_DOUBLE_EQ(post.mean_history_length(), 1.0);
  post.reset();
  post.set_blend_factor(0.5);
  make_frame(1, frame, g);
  post.process(frame, core::GBuffer{}, core::kEveryPixel);
  EXPECT_TRUE(same_bits(post.image(), frame)) << "after a reset the next frame starts the image";
}

TEST(FramePost, TheBlendComesWithoutReprojectionOrFilter) {
  core::FramePostOptions with_reprojection = blend_only();
  with_reprojection.reproject = true;
  core::FramePostOptions with_filter = blend_only();
  with_filter.atrous = true;
  for (const core::FramePostOptions& o : {with_reprojection, with_filter}) {
    EXPECT_THROW(core::HostFramePost{o}, std::invalid_argument);
    EXPECT_THROW(tracers::make_frame_post("host", o), std::invalid_argument);
    if (tracers::device_count("cuda") > 0) {
      EXPECT_THROW(tracers::make_frame_post("cuda:0", o), std::invalid_argument);
    }
  }
}

TEST(FramePost, CudaBlendsAsTheHost) {
  using namespace cohort::test;
  const int gpus = tracers::device_count("cuda");
  if (gpus == 0) GTEST_SKIP() << "no CUDA device (or a build without CUDA)";
  {
    core::HostFramePost host(blend_only());
    std::unique_ptr<core::FramePost> gpu = tracers::make_frame_post("cuda:0", blend_only());
    core::AdaptiveConvergence factors;
    core::FrameBuffer frame;
    core::GBuffer g;
    for (int f = 0; f < 7; ++f) {
      make_frame(f, frame, g);
      const double factor = factors.next_factor(walk_camera(f));
      host.set_blend_factor(factor);
      gpu->set_blend_factor(factor);
      host.process(frame, core::GBuffer{}, core::kEveryPixel);
      gpu->process(frame, core::GBuffer{}, core::kEveryPixel);
      EXPECT_LT(max_relative_difference(gpu->image(), host.image()), 1e-5) << "frame " << f;
    }
  }
  // Path-traced frames without aux planes through the packed merge, the CUDA bands left on their GPUs.
  const int w = 64, h = 48;
  core::BandJob job;
  job.camera = test::test_room_camera(w, h);
  job.previous_camera = job.camera;
  job.params = test::frame_params(K_MODE_PATH, 1, 1, h);
  std::unique_ptr<core::Renderer> room_renderer = gpu_room_renderer(gpus);
  core::Renderer& renderer = *room_renderer;
  std::unique_ptr<core::FramePost> gpu = tracers::make_frame_post("cuda:0", blend_only());
  core::HostFramePost host(blend_only());
  renderer.set_device_bands(gpu->cuda_device());
  core::FrameBuffer floats, untouched;
  for (int f = 0; f < 4; ++f) {
    job.params.frame_index = static_cast<kuint>(f + 1);
    const double factor = 1.0 / (f + 1);
    renderer.set_packed_merge(false);
    renderer.render(job, floats);
    ASSERT_TRUE(renderer.gbuffer().empty());
    host.set_blend_factor(factor);
    host.process(floats, core::GBuffer{}, core::kEveryPixel);
    renderer.set_packed_merge(true);
    renderer.render(job, untouched);
    ASSERT_FALSE(renderer.packed_frame().has_aux());
    EXPECT_EQ(renderer.packed_device_rows().size(), gpus > 1 ? 2u : 1u) << "the CUDA bands stayed on their GPUs";
    gpu->set_blend_factor(factor);
    gpu->process_packed(renderer.packed_frame(), renderer.packed_device_rows(), core::kEveryPixel);
    EXPECT_LT(max_relative_difference(gpu->image(), host.image()), 1e-5) << "frame " << f;
  }
}
