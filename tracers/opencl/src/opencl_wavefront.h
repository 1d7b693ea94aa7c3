// The OpenCL tracer's wavefront (kernel/wavefront.cl): per sample a camera walk, a shading kernel, then per
// bounce a bounce walk and a shading kernel, each shading kernel followed by the shadow walk where it left
// its vertices' shadow rays in their slots; the paths wait in device memory between kernels. The walks are a
// program of their own, built here with their own options (a register cap on NVIDIA); the shading kernels
// are the main program's. Same integrator, same random numbers, same order of float operations: the
// megakernel's image bit for bit, and its row ray counts.
#pragma once

#include <CL/cl.h>

#include <array>
#include <cstddef>
#include <string>

#include "cohort/kernel/layout.h"

namespace cohort::tracers {

class OpenCLWavefront {
 public:
  // The band kernels' arguments, which every wavefront kernel takes first (kernel/band_params.cl: the
  // scene's 13 buffers, the frame's parameters, the camera, the band, its row ray counts).
  static constexpr size_t kBandArgs = 17;
  using BandArgs = std::array<cl_mem, kBandArgs>;

  // shading: the main program (its shading kernels); walk_options: the walk program's build options.
  OpenCLWavefront(cl_context context, cl_device_id device, cl_program shading, const std::string& walk_options,
                  const std::string& label);
  ~OpenCLWavefront();
  OpenCLWavefront(const OpenCLWavefront&) = delete;
  OpenCLWavefront& operator=(const OpenCLWavefront&) = delete;

  // Sets every kernel's arguments for a band of `pixels`, the scratch grown to it: slots, the shadow-ray
  // slots a pixel (k_shadow_queue_slots; 0: the shading kernels walk the shadow rays as they come);
  // first_hits: the aux planes' first-hit records, or null.
  void prepare(const BandArgs& band, size_t pixels, kuint slots, cl_mem first_hits);
  // Enqueues the frame's samples over the band rows [first_row, first_row + rows) of `width` pixels, in
  // whole 8x8 work groups from first_row (the megakernel's launch shape). started / done (may be null):
  // the first and the last kernel's events.
  void enqueue(cl_command_queue queue, const KFrameParams& params, size_t width, size_t first_row, size_t rows,
               cl_event* started, cl_event* done);

 private:
  void release();

  cl_context context_;
  cl_program walk_program_ = nullptr;
  cl_kernel camera_walk_ = nullptr, bounce_walk_ = nullptr, shadow_walk_ = nullptr;
  // Shading builds: [shadow walk][camera rays, camera rays recording first hits, bounce rays].
  std::array<std::array<cl_kernel, 3>, 2> shade_{};
  cl_mem states_ = nullptr, hits_ = nullptr, active_ = nullptr, vertices_ = nullptr, shadow_rays_ = nullptr;
  size_t states_bytes_ = 0, hits_bytes_ = 0, active_bytes_ = 0, vertices_bytes_ = 0, shadow_rays_bytes_ = 0;
  kuint slots_ = 0;
  bool first_hits_ = false;
};

}  // namespace cohort::tracers
