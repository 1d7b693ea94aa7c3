// Tracers by name, for the apps, the benchmarks and the tests alike: "embree", "opencl" / "opencl:N"
// (N-th OpenCL device of all platforms), "cuda" / "cuda:N", "mpi:RANK" (a remote tracer: the bands
// render on that MPI rank's `cohort node`, docs/cluster.md), and the "all" lists. A library of its own
// above the concrete tracers, so that neither the core nor tracers/common depends on them.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "cohort/core/frame_post.h"
#include "cohort/core/tracer.h"

namespace cohort::tracers {

struct TracerSpec {
  std::string kind;  // embree, opencl, cuda, mpi
  int device = 0;    // for mpi: the node's rank
  std::string text;  // as written
  int threads = 0;   // Embree: CPU threads it may use (0: all); parse_tracer_list sets it beside CUDA tracers
};

// The threads an Embree tracer takes when it renders beside CUDA tracers: all but a quarter of the
// hardware threads (at least 2 left), which stay free for the host's share of the frame (merge, the
// post-processing's uploads, tone map) and the GPU tracers' own threads. Measured on nvidia-h100-x2 with
// every thread, Embree slowed the two GPUs' frame by 70% at 1080p with reprojection (docs/balancing.md).
int embree_threads_beside_gpus(unsigned hardware_threads);

// Splits "embree,opencl:1" and expands "all", "cuda:all" and "opencl:all" by probing the devices ("all":
// Embree plus each GPU once, gpu_tracers_for_all in device_listing.h); throws std::invalid_argument naming
// a malformed entry. An Embree entry in a list with a CUDA tracer gets embree_threads_beside_gpus threads.
std::vector<TracerSpec> parse_tracer_list(const std::string& list);

// Throws std::runtime_error when this build lacks the tracer or the device cannot be opened. A remote
// tracer whose node cannot serve is logged and left out of make_tracers' list (it throws when none is left).
std::unique_ptr<core::Tracer> make_tracer(const TracerSpec& spec);
std::vector<std::unique_ptr<core::Tracer>> make_tracers(const std::string& list);
// The same for a list already parsed (parse_tracer_list probes devices for "all": parse once). Logs a
// warning naming both tracers and the PCI bus id when two of them would render on one GPU (cuda:0 and the
// OpenCL device of the same GPU), and still makes them: it may be meant, as a measurement.
std::vector<std::unique_ptr<core::Tracer>> make_tracers(const std::vector<TracerSpec>& specs);

// Opens rank 0's port for nodes that join (docs/cluster.md, "Joining a running session") for the list's
// remote tracers (mpi:N), whose first nodes may take up to `first_wait_s` seconds to come. Call before
// make_tracers (the port asks MPI for MPI_THREAD_MULTIPLE); throws std::invalid_argument where this build
// has no remote tracers or the list names none, std::runtime_error where the port cannot be opened.
void open_node_port(const std::string& port_file, double first_wait_s, const std::vector<TracerSpec>& specs);

// The tracer kinds this binary was built with that render in this process (the remote `mpi` kind is
// not among them: it needs a node on another MPI rank).
std::vector<std::string> built_tracer_kinds();
// Whether this binary has remote tracers (`mpi:RANK`, COHORT_WITH_MPI).
bool remote_tracers_built();

// How many devices of that kind this machine offers the tracer: 1 for Embree (the CPU), 0 for a kind
// this build lacks. Never throws.
int device_count(const std::string& kind);

// The frame's post-processing (core/frame_post.h) at a place: "host" or "cuda:N". Throws
// std::invalid_argument for a malformed place, std::runtime_error when this build or machine lacks it.
std::unique_ptr<core::FramePost> make_frame_post(const std::string& where, const core::FramePostOptions& options);

// Where `--post-on auto` runs it: the GPU of the first CUDA tracer (it holds the frame's device memory
// and the bus to it), else the host.
std::string auto_frame_post_place(const std::vector<TracerSpec>& tracers);

// What `--aux-rays auto` picks (core::aux_rays_mode's names): "first-hit" where a CUDA tracer renders and no
// OpenCL or remote (mpi) tracer does, "centre" otherwise. First hits spare a CUDA GPU the second camera ray
// (about 0.8 ms a 1080p frame on an H100) at equal quality (docs/denoising.md); an OpenCL tracer finishes
// and reads them only after its band (slower in a mix), a node's tracers are not known here, and on the
// CPU alone Embree's centre-ray packets cost about as little as the finisher.
std::string auto_aux_rays(const std::vector<TracerSpec>& tracers);

}  // namespace cohort::tracers
