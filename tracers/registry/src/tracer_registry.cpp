#include "cohort/tracers/tracer_registry.h"

#include <algorithm>
#include <cstdlib>
#include <stdexcept>
#include <thread>

#include <spdlog/spdlog.h>

#include "cohort/tracers/device_listing.h"

#ifdef COHORT_HAVE_EMBREE
#include "cohort/tracers/embree_tracer.h"
#endif
#ifdef COHORT_HAVE_OPENCL
#include "cohort/tracers/opencl_tracer.h"
#endif
#ifdef COHORT_HAVE_CUDA
#include "cohort/tracers/cuda_tracer.h"
#include "cohort/tracers/cuda_frame_post.h"
#endif
#ifdef COHORT_HAVE_MPI
#include <cstdlib>

#include "cohort/tracers/mpi_tracer.h"
#include "cohort/tracers/mpi_node_port.h"
#endif

namespace cohort::tracers {

namespace {

TracerSpec spec_of(const std::string& kind, int device) {
  TracerSpec spec;
  spec.kind = kind;
  spec.device = device;
  spec.text = kind == "embree" ? kind : kind + ":" + std::to_string(device);
  return spec;
}

// "all": Embree on the CPU plus every GPU once (gpu_tracers_for_all: CUDA devices, then OpenCL devices
// on other GPUs). "cuda:all" / "opencl:all": every device of that kind (PoCL's CPU device included).
std::vector<TracerSpec> expand_all(const std::string& item) {
  std::vector<TracerSpec> specs;
  if (item == "cuda:all") {
    for (int d = 0, n = device_count("cuda"); d < n; ++d) specs.push_back(spec_of("cuda", d));
    if (specs.empty()) throw std::invalid_argument("cuda:all: no CUDA device on this machine");
    return specs;
  }
  if (item == "opencl:all") {
    for (int d = 0, n = device_count("opencl"); d < n; ++d) specs.push_back(spec_of("opencl", d));
    if (specs.empty()) throw std::invalid_argument("opencl:all: no OpenCL device on this machine");
    return specs;
  }
#ifdef COHORT_HAVE_EMBREE
  specs.push_back(spec_of("embree", 0));
#endif
  for (const std::string& gpu : gpu_tracers_for_all(list_tracer_devices())) {
    const size_t colon = gpu.find(':');
    specs.push_back(spec_of(gpu.substr(0, colon), std::stoi(gpu.substr(colon + 1))));
  }
  if (specs.empty()) {
    // A build without Embree on a machine without GPUs: PoCL's CPU device is all there is.
    for (TracerSpec& s : expand_all("opencl:all")) specs.push_back(s);
  }
  return specs;
}

// Warns about requested tracers that would share a GPU (cuda:0 and opencl:1 are often one device).
void warn_about_shared_gpus(const std::vector<TracerSpec>& specs) {
  size_t gpu_specs = 0;
  for (const TracerSpec& s : specs) gpu_specs += s.kind == "cuda" || s.kind == "opencl" ? 1u : 0u;
  if (gpu_specs < 2) return;
  const std::vector<TracerDevice> devices = list_tracer_devices();
  std::vector<TracerDevice> requested;
  for (const TracerSpec& s : specs) {
    if (s.kind != "cuda" && s.kind != "opencl") continue;
    const std::string name = s.kind + ":" + std::to_string(s.device);
    auto found = std::find_if(devices.begin(), devices.end(), [&](const TracerDevice& d) { return d.tracer == name; });
    requested.push_back(found != devices.end() ? *found : TracerDevice{name, "", DeviceKind::other, {}});
  }
  for (const SharedGpu& shared : tracers_sharing_a_gpu(requested)) spdlog::warn("{}", shared_gpu_warning(shared));
}

}  // namespace

std::vector<TracerSpec> parse_tracer_list(const std::string& list) {
  std::vector<TracerSpec> specs;
  size_t start = 0;
  while (start <= list.size()) {
    size_t comma = list.find(',', start);
    std::string item = list.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    start = comma == std::string::npos ? list.size() + 1 : comma + 1;
    if (item.empty()) continue;
    if (item == "all" || item == "cuda:all" || item == "opencl:all") {
      for (TracerSpec& expanded : expand_all(item)) specs.push_back(expanded);
      continue;
    }
    TracerSpec spec;
    spec.text = item;
    size_t colon = item.find(':');
    spec.kind = item.substr(0, colon);
    if (colon != std::string::npos) {
      std::string index = item.substr(colon + 1);
      if (index.empty() || index.find_first_not_of("0123456789") != std::string::npos)
        throw std::invalid_argument("tracer '" + item + "': the device after ':' must be a number");
      spec.device = std::stoi(index);
    }
    if (spec.kind != "embree" && spec.kind != "opencl" && spec.kind != "cuda" && spec.kind != "mpi")
      throw std::invalid_argument("unknown tracer '" + item + "' (known: embree, opencl[:N], cuda[:N], mpi:RANK)");
    if (spec.kind == "mpi" && (colon == std::string::npos || spec.device < 1))
      throw std::invalid_argument("tracer '" + item + "': a remote tracer names its node's MPI rank, 1 or more (mpi:1)");
    // Two tracers on one node would take each other's answers: a node serves one remote tracer.
    for (const TracerSpec& earlier : specs)
      if (spec.kind == "mpi" && earlier.kind == "mpi" && earlier.device == spec.device)
        throw std::invalid_argument("tracer '" + item + "' is named twice: a node serves one remote tracer (give it "
                                    "several local tracers with `cohort node --tracers`)");
    if (spec.kind == "embree" && colon != std::string::npos)
      throw std::invalid_argument("tracer '" + item + "': the Embree tracer takes no device index");
    specs.push_back(spec);
  }
  if (specs.empty()) throw std::invalid_argument("no tracers named in '" + list + "'");
  bool any_cuda = false;
  for (const TracerSpec& s : specs) any_cuda = any_cuda || s.kind == "cuda";
  if (any_cuda)
    for (TracerSpec& s : specs)
      if (s.kind == "embree") s.threads = embree_threads_beside_gpus(std::thread::hardware_concurrency());
  return specs;
}

int embree_threads_beside_gpus(unsigned hardware_threads) {
  const int all = static_cast<int>(std::max(hardware_threads, 1u));
  return std::max(1, all - std::max(2, all / 4));
}

namespace {

// An on/off environment switch: 0 or 1, `otherwise` when unset or empty; anything else is named.
[[maybe_unused]] bool env_switch(const char* variable, bool otherwise) {
  const char* value = std::getenv(variable);
  if (!value || !*value) return otherwise;
  if (std::string(value) != "0" && std::string(value) != "1")
    throw std::invalid_argument(std::string(variable) + "='" + value + "': expected 0 or 1");
  return std::string(value) == "1";
}

// A register cap for an OpenCL program: 0 (none) to 255, `otherwise` when unset or empty.
[[maybe_unused]] int env_registers(const char* variable, int otherwise) {
  const char* value = std::getenv(variable);
  if (!value || !*value) return otherwise;
  char* end = nullptr;
  const long count = std::strtol(value, &end, 10);
  if (*end != '\0' || count < 0 || count > 255)
    throw std::invalid_argument(std::string(variable) + "='" + value + "': expected a register count from 0 (no cap) to 255");
  return static_cast<int>(count);
}

}  // namespace

std::unique_ptr<core::Tracer> make_tracer(const TracerSpec& spec) {
#ifdef COHORT_HAVE_EMBREE
  if (spec.kind == "embree") return std::make_unique<EmbreeTracer>(spec.threads);
#endif
#ifdef COHORT_HAVE_OPENCL
  if (spec.kind == "opencl") {
    OpenCLTracer::Options options;
    options.device = spec.device;
    // For A/B runs of the first-hit pieces (1: the whole band, then its aux work) without a rebuild.
    if (const char* pieces = std::getenv("COHORT_OPENCL_FIRST_HIT_PIECES"); pieces && *pieces) {
      char* end = nullptr;
      const long count = std::strtol(pieces, &end, 10);
      if (*end != '\0' || count < 1 || count > OpenCLTracer::kMaxFirstHitPieces)
        throw std::invalid_argument("COHORT_OPENCL_FIRST_HIT_PIECES='" + std::string(pieces) + "': expected a count from 1 to " +
                                    std::to_string(OpenCLTracer::kMaxFirstHitPieces));
      options.first_hit_pieces = static_cast<int>(count);
    }
    if (const char* into = std::getenv("COHORT_OPENCL_AUX_INTO_TARGET"); into && *into) {
      if (std::string(into) != "0" && std::string(into) != "1")
        throw std::invalid_argument("COHORT_OPENCL_AUX_INTO_TARGET='" + std::string(into) + "': expected 0 or 1");
      options.aux_into_target = std::string(into) == "1";
    }
    // The wavefront against the megakernel, and its register caps on NVIDIA, for A/B runs without a rebuild.
    if (const char* wave = std::getenv("COHORT_OPENCL_WAVEFRONT"); wave && *wave)
      options.wavefront = env_switch("COHORT_OPENCL_WAVEFRONT", true) ? OpenCLTracer::Options::Wavefront::always
                                                                       : OpenCLTracer::Options::Wavefront::never;
    options.shadow_walk = env_switch("COHORT_OPENCL_SHADOW_WALK", options.shadow_walk);
    options.wave_lanes = env_switch("COHORT_OPENCL_WAVE_LANES", options.wave_lanes);
    options.enqueue_ahead = env_switch("COHORT_OPENCL_ENQUEUE_AHEAD", options.enqueue_ahead);
    if (const char* transfer = std::getenv("COHORT_OPENCL_TRANSFER_QUEUE"); transfer && *transfer)
      options.transfer_queue = env_switch("COHORT_OPENCL_TRANSFER_QUEUE", true) ? OpenCLTracer::Options::TransferQueue::always
                                                                              : OpenCLTracer::Options::TransferQueue::never;
    options.pinned_band_reads = env_switch("COHORT_OPENCL_PINNED_READS", options.pinned_band_reads);
    options.late_job_cost = env_switch("COHORT_OPENCL_LATE_JOB_COST", options.late_job_cost);
    options.walk_registers = env_registers("COHORT_OPENCL_WALK_REGISTERS", options.walk_registers);
    options.shade_registers = env_registers("COHORT_OPENCL_SHADE_REGISTERS", options.shade_registers);
    return std::make_unique<OpenCLTracer>(options);
  }
#endif
#ifdef COHORT_HAVE_CUDA
  if (spec.kind == "cuda") return std::make_unique<CudaTracer>(spec.device);
#endif
#ifdef COHORT_HAVE_MPI
  if (spec.kind == "mpi") {
    MpiTracerOptions options;
    options.rank = spec.device;
    if (const char* ms = std::getenv("COHORT_MPI_BAND_TIMEOUT_MS"); ms && *ms)
      options.band_timeout = std::chrono::milliseconds(std::max(1L, std::atol(ms)));
    if (const char* pieces = std::getenv("COHORT_MPI_BAND_PIECES"); pieces && *pieces)
      options.pieces = uint32_t(std::clamp(std::atol(pieces), 1L, long(wire::kMaxPieces)));
    if (const char* ahead = std::getenv("COHORT_MPI_COMMITS_AHEAD"); ahead && *ahead)
      options.commits_ahead = std::string(ahead) != "0";
    if (const char* ahead = std::getenv("COHORT_MPI_JOBS_AHEAD"); ahead && *ahead)
      options.jobs_ahead = std::string(ahead) != "0";
    if (const char* warm = std::getenv("COHORT_MPI_WARM_UP"); warm && *warm)
      options.warm_up = std::string(warm) != "0";
    return std::make_unique<MpiTracer>(options);
  }
#endif
  throw std::runtime_error("tracer '" + spec.text + "' is not built into this binary" +
                           (spec.kind == "mpi" ? " (configure with MPI found: COHORT_WITH_MPI)" : ""));
}

std::vector<std::unique_ptr<core::Tracer>> make_tracers(const std::string& list) {
  return make_tracers(parse_tracer_list(list));
}

std::vector<std::unique_ptr<core::Tracer>> make_tracers(const std::vector<TracerSpec>& specs) {
  warn_about_shared_gpus(specs);
  std::vector<std::unique_ptr<core::Tracer>> out;
  std::vector<std::string> left;
  for (const TracerSpec& spec : specs) {
#ifdef COHORT_HAVE_MPI
    // A node that cannot serve (its scene failed to load, another version) leaves the set; the
    // others render without it.
    try {
      out.push_back(make_tracer(spec));
    } catch (const NodeUnavailable& e) {
      spdlog::error("{}", e.what());
      left.push_back(e.what());
    }
#else
    out.push_back(make_tracer(spec));
#endif
  }
  if (out.empty()) {
    std::string named;
    for (const TracerSpec& spec : specs) named += (named.empty() ? "" : ",") + spec.text;
    throw std::runtime_error("no tracer could start: " + (left.empty() ? named : left.front()));
  }
  return out;
}

std::vector<std::string> built_tracer_kinds() {
  std::vector<std::string> kinds;
#ifdef COHORT_HAVE_EMBREE
  kinds.push_back("embree");
#endif
#ifdef COHORT_HAVE_OPENCL
  kinds.push_back("opencl");
#endif
#ifdef COHORT_HAVE_CUDA
  kinds.push_back("cuda");
#endif
  return kinds;
}

bool remote_tracers_built() {
#ifdef COHORT_HAVE_MPI
  return true;
#else
  return false;
#endif
}

void open_node_port(const std::string& port_file, double first_wait_s, const std::vector<TracerSpec>& specs) {
  std::vector<int> slots;
  for (const TracerSpec& spec : specs)
    if (spec.kind == "mpi") slots.push_back(spec.device);
  if (slots.empty())
    throw std::invalid_argument("--node-port: no remote tracer (mpi:N) in the tracer list for nodes to serve");
#ifdef COHORT_HAVE_MPI
  NodePort::open(port_file, std::chrono::milliseconds(int64_t(first_wait_s * 1000.0)), slots);
#else
  (void)port_file, (void)first_wait_s;
  throw std::invalid_argument("--node-port: this build has no MPI (docs/cluster.md)");
#endif
}

int device_count(const std::string& kind) {
#ifdef COHORT_HAVE_EMBREE
  if (kind == "embree") return 1;
#endif
#ifdef COHORT_HAVE_OPENCL
  if (kind == "opencl") return int(OpenCLTracer::list_devices().size());
#endif
#ifdef COHORT_HAVE_CUDA
  if (kind == "cuda") return cuda_device_count();
#endif
  return 0;
}

std::unique_ptr<core::FramePost> make_frame_post(const std::string& where, const core::FramePostOptions& options) {
  if (where == "host") return std::make_unique<core::HostFramePost>(options);
  if (where.rfind("cuda", 0) == 0) {
    const std::vector<TracerSpec> specs = parse_tracer_list(where);
    if (specs.size() != 1 || specs[0].kind != "cuda")
      throw std::invalid_argument("frame post: '" + where + "' names no single CUDA device (cuda:N)");
#ifdef COHORT_HAVE_CUDA
    return make_cuda_frame_post(specs[0].device, options);
#else
    throw std::runtime_error("frame post on " + where + ": this build has no CUDA (configure with COHORT_WITH_CUDA=ON)");
#endif
  }
  throw std::invalid_argument("frame post: unknown place '" + where + "' (host or cuda:N)");
}

std::string auto_aux_rays(const std::vector<TracerSpec>& tracers) {
  bool cuda = false;
  for (const TracerSpec& t : tracers) {
    if (t.kind == "opencl" || t.kind == "mpi") return "centre";
    cuda = cuda || t.kind == "cuda";
  }
  return cuda ? "first-hit" : "centre";
}

std::string auto_frame_post_place(const std::vector<TracerSpec>& tracers) {
  for (const TracerSpec& t : tracers)
    if (t.kind == "cuda") return "cuda:" + std::to_string(t.device);
  return "host";
}

}  // namespace cohort::tracers
