#include "opencl_wavefront.h"

#include <vector>

#include "cohort/kernel/path_pattern.h"
#include "cohort/kernel/path_state.h"
#include "cohort/kernel/scene_view.h"
#include "cohort/kernel/shadow_ray.h"
#include "opencl_support.h"

namespace cohort::tracers {

namespace opencl_source {
extern const char* const kWavefrontWalk;
}

namespace {

// The arguments after the band's (kernel/wavefront.cl, COHORT_WAVE_KERNEL_PARAMS).
constexpr cl_uint kStatesArg = OpenCLWavefront::kBandArgs, kHitsArg = kStatesArg + 1, kActiveArg = kStatesArg + 2,
                  kVerticesArg = kStatesArg + 3, kShadowRaysArg = kStatesArg + 4, kStrideArg = kStatesArg + 5,
                  kSampleArg = kStatesArg + 6, kFirstHitsArg = kStatesArg + 7;

}  // namespace

OpenCLWavefront::OpenCLWavefront(cl_context context, cl_device_id device, cl_program shading,
                                 const std::string& walk_options, const std::string& label)
    : context_(context) {
  try {
    walk_program_ =
        build_program(context, device, opencl_source::kWavefrontWalk, "wavefront_walk", walk_options, label);
    camera_walk_ = create_kernel(walk_program_, "cohort_wave_camera_walk");
    bounce_walk_ = create_kernel(walk_program_, "cohort_wave_bounce_walk");
    shadow_walk_ = create_kernel(walk_program_, "cohort_wave_shadow_walk");
    const char* names[2][3] = {
        {"cohort_wave_shade_camera", "cohort_wave_shade_camera_first_hits", "cohort_wave_shade_bounce"},
        {"cohort_wave_shade_camera_shadow_walk", "cohort_wave_shade_camera_first_hits_shadow_walk",
         "cohort_wave_shade_bounce_shadow_walk"}};
    for (int walk = 0; walk < 2; ++walk)
      for (int k = 0; k < 3; ++k) shade_[walk][k] = create_kernel(shading, names[walk][k]);
  } catch (...) {
    release();
    throw;
  }
}

OpenCLWavefront::~OpenCLWavefront() { release(); }

void OpenCLWavefront::release() {
  for (cl_mem m : {states_, hits_, active_, vertices_, shadow_rays_})
    if (m) clReleaseMemObject(m);
  for (const auto& builds : shade_)
    for (cl_kernel k : builds)
      if (k) clReleaseKernel(k);
  for (cl_kernel k : {camera_walk_, bounce_walk_, shadow_walk_})
    if (k) clReleaseKernel(k);
  if (walk_program_) clReleaseProgram(walk_program_);
}

void OpenCLWavefront::prepare(const BandArgs& band, size_t pixels, kuint slots, cl_mem first_hits) {
  grow_buffer(context_, states_, states_bytes_, pixels * sizeof(KPathState), "clCreateBuffer(wavefront states)");
  grow_buffer(context_, hits_, hits_bytes_, pixels * sizeof(KHit), "clCreateBuffer(wavefront hits)");
  grow_buffer(context_, active_, active_bytes_, pixels * sizeof(kuint), "clCreateBuffer(wavefront flags)");
  cl_mem vertices = nullptr, shadow_rays = nullptr;
  if (slots > 0u) {
    vertices = grow_buffer(context_, vertices_, vertices_bytes_, pixels * sizeof(KVertexLight),
                           "clCreateBuffer(wavefront vertices)");
    shadow_rays = grow_buffer(context_, shadow_rays_, shadow_rays_bytes_, pixels * slots * sizeof(KShadowRay),
                              "clCreateBuffer(wavefront shadow rays)");
  }
  slots_ = slots;
  first_hits_ = first_hits != nullptr;
  const cl_uint stride = static_cast<cl_uint>(pixels);
  const cl_uint sample = 0;
  auto set = [&](cl_kernel k) {
    for (cl_uint a = 0; a < kBandArgs; ++a) check(clSetKernelArg(k, a, sizeof(cl_mem), &band[a]), "clSetKernelArg(wavefront)");
    const cl_mem scratch[] = {states_, hits_, active_, vertices, shadow_rays};
    for (cl_uint a = 0; a < 5; ++a)
      check(clSetKernelArg(k, kStatesArg + a, sizeof(cl_mem), &scratch[a]), "clSetKernelArg(wavefront scratch)");
    check(clSetKernelArg(k, kStrideArg, sizeof stride, &stride), "clSetKernelArg(wavefront stride)");
    check(clSetKernelArg(k, kSampleArg, sizeof sample, &sample), "clSetKernelArg(wavefront sample)");
    check(clSetKernelArg(k, kFirstHitsArg, sizeof(cl_mem), &first_hits), "clSetKernelArg(wavefront first hits)");
  };
  for (cl_kernel k : {camera_walk_, bounce_walk_, shadow_walk_}) set(k);
  for (const auto& builds : shade_)
    for (cl_kernel k : builds) set(k);
}

void OpenCLWavefront::enqueue(cl_command_queue queue, const KFrameParams& params, size_t width, size_t first_row,
                              size_t rows, cl_event* started, cl_event* done) {
  const size_t local[2] = {8, 8};
  const size_t offset[2] = {0, first_row};
  const size_t global[2] = {(width + 7) / 8 * 8, (rows + 7) / 8 * 8};
  // The latest kernel's event, released however this leaves unless handed out as `done`.
  struct LastEvent {
    cl_event event = nullptr;
    ~LastEvent() {
      if (event) clReleaseEvent(event);
    }
  } last;
  const int walk = slots_ > 0u ? 1 : 0;
  // The band's kernels in order, on one in-order queue: per sample the camera walk, then per stage (the camera
  // rays', each bounce's, after its bounce walk) a shading kernel and, with slots, the shadow walk. Each but the
  // bounce walk has its sample argument set just before its launch.
  struct Launch {
    cl_kernel kernel;
    bool takes_sample;
    cl_uint sample;
  };
  std::vector<Launch> launches;
  const kuint spp = k_paths_per_pixel(params.spp);
  for (cl_uint sample = 0; sample < spp; ++sample) {
    launches.push_back({camera_walk_, true, sample});
    for (kuint bounce = 0u; bounce <= params.max_bounces; ++bounce) {
      if (bounce > 0u) launches.push_back({bounce_walk_, false, 0u});
      const int build = bounce > 0u ? 2 : sample == 0u && first_hits_ ? 1 : 0;
      launches.push_back({shade_[walk][build], true, sample});
      if (walk) launches.push_back({shadow_walk_, true, sample});
    }
  }
  // Only the first (started) and the last (done) ask for an event: an event is a driver object made and recorded
  // per launch, host time in front of the band.
  for (size_t i = 0; i < launches.size(); ++i) {
    const Launch& l = launches[i];
    if (l.takes_sample)
      check(clSetKernelArg(l.kernel, kSampleArg, sizeof l.sample, &l.sample), "clSetKernelArg(wavefront sample)");
    const bool first = i == 0 && started && !*started, final = i + 1 == launches.size() && done;
    cl_event event = nullptr;
    check(clEnqueueNDRangeKernel(queue, l.kernel, 2, offset, global, local, 0, nullptr,
                                 first || final ? &event : nullptr),
          "launching a wavefront kernel");
    if (first && clRetainEvent(event) == CL_SUCCESS) *started = event;
    if (event) {
      if (last.event) clReleaseEvent(last.event);
      last.event = event;
    }
  }
  if (done) {
    *done = last.event;
    last.event = nullptr;
  }
}

}  // namespace cohort::tracers
