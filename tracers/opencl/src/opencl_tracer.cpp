#include "cohort/tracers/opencl_tracer.h"

#include <CL/cl.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <chrono>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include <spdlog/spdlog.h>

#include "cohort/core/host_threads.h"
#include "cohort/kernel/aux_mode.h"
#include "cohort/kernel/path_state.h"
#include "cohort/kernel/shadow_ray.h"
#include "cohort/tracers/enqueue_ahead.h"
#include "cohort/tracers/wave_lanes.h"
#include "opencl_support.h"
#include "opencl_wavefront.h"

namespace cohort::tracers {

namespace opencl_source {
extern const char* const kRenderBand;
}

namespace {

// A string property of a platform or device: OpenCL's query-the-size-then-fill pattern.
template <typename Object, typename Info>
std::string info_string(cl_int (*query)(Object, Info, size_t, void*, size_t*), Object object, Info what) {
  size_t n = 0;
  query(object, what, 0, nullptr, &n);
  std::string s(n, '\0');
  query(object, what, n, s.data(), nullptr);
  while (!s.empty() && s.back() == '\0') s.pop_back();
  return s;
}

std::string platform_info(cl_platform_id p, cl_platform_info what) { return info_string(&clGetPlatformInfo, p, what); }
std::string device_info(cl_device_id d, cl_device_info what) { return info_string(&clGetDeviceInfo, d, what); }

bool lists_extension(const std::string& extensions, const std::string& name) {
  size_t at = 0;
  while ((at = extensions.find(name, at)) != std::string::npos) {
    const size_t end = at + name.size();
    if ((at == 0 || extensions[at - 1] == ' ') && (end == extensions.size() || extensions[end] == ' ')) return true;
    at = end;
  }
  return false;
}

// The extensions' query values, spelled out: older OpenCL headers lack them.
constexpr cl_device_info kPciBusInfoKhr = 0x410F;  // cl_khr_pci_bus_info: cl_device_pci_bus_info_khr
constexpr cl_device_info kPciBusIdNv = 0x4008;     // cl_nv_device_attribute_query
constexpr cl_device_info kPciSlotIdNv = 0x4009;    // device << 3 | function
constexpr cl_device_info kPciDomainIdNv = 0x400A;  // newer drivers only

// The device's PCI address where it lists an extension that tells it; asked only then, since drivers
// answer unknown queries inconsistently.
PciBusId pci_bus_id(cl_device_id d) {
  const std::string extensions = device_info(d, CL_DEVICE_EXTENSIONS);
  if (lists_extension(extensions, "cl_khr_pci_bus_info")) {
    struct {
      cl_uint domain, bus, device, function;
    } info{};
    if (clGetDeviceInfo(d, kPciBusInfoKhr, sizeof info, &info, nullptr) == CL_SUCCESS)
      return PciBusId::of(info.domain, info.bus, info.device, info.function);
  }
  if (lists_extension(extensions, "cl_nv_device_attribute_query")) {
    cl_uint bus = 0, slot = 0, domain = 0;
    if (clGetDeviceInfo(d, kPciBusIdNv, sizeof bus, &bus, nullptr) == CL_SUCCESS &&
        clGetDeviceInfo(d, kPciSlotIdNv, sizeof slot, &slot, nullptr) == CL_SUCCESS) {
      if (clGetDeviceInfo(d, kPciDomainIdNv, sizeof domain, &domain, nullptr) == CL_SUCCESS)
        return PciBusId::of(domain, bus & 0xffu, (slot >> 3) & 0x1fu, slot & 7u);
      return PciBusId::without_domain(bus & 0xffu, (slot >> 3) & 0x1fu, slot & 7u);
    }
  }
  return {};
}

struct DeviceEntry {
  cl_platform_id platform;
  cl_device_id device;
  std::string label;
};

std::vector<DeviceEntry> all_devices() {
  std::vector<DeviceEntry> out;
  cl_uint np = 0;
  if (clGetPlatformIDs(0, nullptr, &np) != CL_SUCCESS || np == 0) return out;
  std::vector<cl_platform_id> platforms(np);
  clGetPlatformIDs(np, platforms.data(), nullptr);
  for (cl_platform_id p : platforms) {
    cl_uint nd = 0;
    if (clGetDeviceIDs(p, CL_DEVICE_TYPE_ALL, 0, nullptr, &nd) != CL_SUCCESS || nd == 0) continue;
    std::vector<cl_device_id> devices(nd);
    clGetDeviceIDs(p, CL_DEVICE_TYPE_ALL, nd, devices.data(), nullptr);
    for (cl_device_id d : devices)
      out.push_back({p, d, platform_info(p, CL_PLATFORM_NAME) + " / " + device_info(d, CL_DEVICE_NAME)});
  }
  return out;
}

// A device buffer holding a copy of a host array (at least 16 bytes: OpenCL refuses empty buffers).
class DeviceBuffer {
 public:
  DeviceBuffer() = default;
  DeviceBuffer(const DeviceBuffer&) = delete;
  DeviceBuffer& operator=(const DeviceBuffer&) = delete;
  ~DeviceBuffer() {
    settle();
    reset();
  }
  void reset() {
    if (mem_) clReleaseMemObject(mem_);
    mem_ = nullptr;
    bytes_ = 0;
  }
  // blocking: CL_FALSE only where `data` stays untouched until the queue is finished. staged: `data` copied
  // here and written from the copy without blocking, the copy kept until the write is done (a commit applied
  // ahead, while the band before is still in the queue: a blocking write would wait for that band, and the
  // scene's arrays change with the next commit).
  template <class T>
  void upload(cl_context context, cl_command_queue queue, const std::vector<T>& data, const char* what,
              cl_bool blocking = CL_TRUE, bool staged = false) {
    size_t bytes = std::max<size_t>(data.size() * sizeof(T), 16);
    if (bytes > bytes_) {
      reset();
      cl_int err = CL_SUCCESS;
      // Read-write: the skinning kernels write vertices and BLAS nodes in place.
      mem_ = clCreateBuffer(context, CL_MEM_READ_WRITE, bytes, nullptr, &err);
      check(err, what);
      bytes_ = bytes;
    }
    if (data.empty()) return;
    if (staged) {
      settle();
      const auto* from = reinterpret_cast<const unsigned char*>(data.data());
      staged_.assign(from, from + data.size() * sizeof(T));
      check(clEnqueueWriteBuffer(queue, mem_, CL_FALSE, 0, staged_.size(), staged_.data(), 0, nullptr, &written_), what);
      return;
    }
    check(clEnqueueWriteBuffer(queue, mem_, blocking, 0, data.size() * sizeof(T), data.data(), 0, nullptr, nullptr),
          what);
  }
  cl_mem mem() const { return mem_; }

 private:
  // The last staged write done (and its copy free to go or be overwritten).
  void settle() {
    if (!written_) return;
    clWaitForEvents(1, &written_);
    clReleaseEvent(written_);
    written_ = nullptr;
  }
  cl_mem mem_ = nullptr;
  size_t bytes_ = 0;
  std::vector<unsigned char> staged_;
  cl_event written_ = nullptr;
};

// An event the tracer waits on or times, released when it goes out of scope (also on a throw).
class Event {
 public:
  Event() = default;
  Event(const Event&) = delete;
  Event& operator=(const Event&) = delete;
  ~Event() {
    if (event_) clReleaseEvent(event_);
  }
  cl_event* out() {
    if (event_) clReleaseEvent(event_);
    event_ = nullptr;
    return &event_;
  }
  cl_event get() const { return event_; }
  // Holds `other`'s event too, retained: one command's event under two names.
  void share(const Event& other) {
    check(clRetainEvent(other.event_), "clRetainEvent");
    *out() = other.event_;
  }
  // Takes `other`'s event over (a band's own copy of an event the tracer keeps for the band being enqueued).
  void take(Event& other) {
    if (event_) clReleaseEvent(event_);
    event_ = other.event_;
    other.event_ = nullptr;
  }
  // The command's start or end on the device clock (the queue profiles), 0 when unknown.
  cl_ulong time(cl_profiling_info which) const {
    cl_ulong t = 0;
    if (event_ && clGetEventProfilingInfo(event_, which, sizeof t, &t, nullptr) != CL_SUCCESS) t = 0;
    return t;
  }

 private:
  cl_event event_ = nullptr;
};

// Page-locked host memory the device copies into by DMA while kernels run (CL_MEM_ALLOC_HOST_PTR, mapped
// once and kept mapped: the drivers' pattern for asynchronous reads; a read into pageable memory goes
// through the driver's own staging and may not overlap anything).
class PinnedStaging {
 public:
  PinnedStaging() = default;
  PinnedStaging(const PinnedStaging&) = delete;
  PinnedStaging& operator=(const PinnedStaging&) = delete;
  ~PinnedStaging() { reset(); }
  void reset() {
    if (mem_ && host_) {
      clEnqueueUnmapMemObject(queue_, mem_, host_, 0, nullptr, nullptr);
      clFinish(queue_);
    }
    if (mem_) clReleaseMemObject(mem_);
    mem_ = nullptr;
    host_ = nullptr;
    bytes_ = 0;
  }
  // At least `bytes` of it (contents lost when it grows); queue: where it is mapped and unmapped.
  void* reserve(cl_context context, cl_command_queue queue, size_t bytes, const char* what) {
    if (bytes <= bytes_) return host_;
    reset();
    cl_int err = CL_SUCCESS;
    mem_ = clCreateBuffer(context, CL_MEM_READ_WRITE | CL_MEM_ALLOC_HOST_PTR, bytes, nullptr, &err);
    check(err, what);
    queue_ = queue;
    host_ = clEnqueueMapBuffer(queue, mem_, CL_TRUE, CL_MAP_READ | CL_MAP_WRITE, 0, bytes, 0, nullptr, nullptr, &err);
    check(err, what);
    bytes_ = bytes;
    return host_;
  }
  void* host() const { return host_; }

 private:
  cl_mem mem_ = nullptr;
  cl_command_queue queue_ = nullptr;
  void* host_ = nullptr;
  size_t bytes_ = 0;
};

// Every queue a band's commands go on (Impl::queues); absent ones are null.
using BandQueues = std::array<cl_command_queue, 5>;

void finish_all(const BandQueues& queues) {
  for (cl_command_queue q : queues)
    if (q) clFinish(q);
}

}  // namespace

struct OpenCLTracer::EnqueuedBand {
  core::BandJob job;  // as handed over: render_band matches the next job against it
  core::BandBuffer* target = nullptr;
  // Written to the device without blocking and read into without blocking: kept until the band is done.
  KFrameParams params{};
  KCamera camera{};
  std::vector<float> band;  // a band narrower than the target, read before it is stored row by row
  std::vector<cl_uint> row_rays;
  // Options::pinned_band_reads: where the band's colour was read to, copied into its target rows once read.
  const void* staged = nullptr;
  size_t staged_bytes = 0;
  const void* staged_row_rays = nullptr;
  size_t rows = 0;
  bool straight = false, write_aux = false, aux_from_paths = false;
  bool whole_band = false;  // its rows end where the frame's do (row_work is reported then)
  OpenCLWavefront* wave = nullptr;
  Event band_started, band_done, band_read, last;  // last: the band's last command (the row counts' read, or with the transfer queues the band's)
  // The band's last kernel (the packing, or the band's own last kernel): its reads wait on it on the read
  // queue (Options::transfer_queue), and the next band's device gap is timed from its end.
  Event kernels_done;
  // With aux planes from centre rays: the aux kernel (the band's clock starts there) and the texels' read
  // into page-locked staging, taken over from Impl's once enqueued, so that the next band's may follow.
  Event aux_kernel_done, aux_read;
  double enqueue_ms = 0.0;  // the host's time enqueueing it (enqueue_band), for the debug log
  bool ahead = false;       // enqueued ahead, inside the band before
  // On the device, from the band before's last kernel to this band's first, when the band before was this
  // tracer's previous band (for the debug log); negative when unknown.
  double gap_ms = -1.0;
};

struct OpenCLTracer::Impl {
  std::string label;
  bool gpu = false;
  cl_device_id device = nullptr;
  cl_context context = nullptr;
  cl_command_queue queue = nullptr;
  // The aux texels' read runs on this second in-order queue, behind the aux kernel's event, while the
  // band's kernel runs on `queue` (CUDA's aux copy stream).
  cl_command_queue aux_queue = nullptr;
  cl_program program = nullptr;
  cl_kernel kernel = nullptr, aux_kernel = nullptr;
  // The aux texels' copy out of page-locked staging into the target: tens of MB a band at 1080p, on
  // threads of its own (1.35 ms median on nvidia-h100-x2, docs/balancing.md), not the shared pool, which
  // the core's merge and tone map hold while this band renders.
  core::HostThreads aux_copy_threads{3};
  int first_hit_pieces = 1;  // Options::first_hit_pieces
  bool aux_into_target = false;  // Options::aux_into_target
  DeviceBuffer previous_transforms, previous_joints;
  DeviceBuffer vertices, vertex_colors, triangles, blas_nodes, blases, instances, tlas_nodes, materials, textures, texels, lights, light_nodes,
      emissive;
  DeviceBuffer skins, skin_vertices, skin_weights, skin_triangles, skin_adjacency, skin_faces, joints;
  cl_kernel skin_positions = nullptr, skin_faces_kernel = nullptr, skin_normals = nullptr, refit_leaves = nullptr,
            refit_blas = nullptr;

  // Poses the given skins on the device: positions, then normals, then the BLAS refit (in queue order).
  void run_skinning(const commit::TracerScene& s, const std::vector<uint32_t>& which) {
    for (uint32_t index : which) {
      if (index >= s.skins.size()) continue;
      const KSkin& skin = s.skins[index];
      if (skin.vertex_count == 0 || size_t(skin.joint_offset) + skin.joint_count > s.joints.size()) continue;
      const cl_uint skin_index = index;
      const size_t local = 64, global = (size_t(skin.vertex_count) + local - 1) / local * local;
      const cl_mem position_args[] = {vertices.mem(), skin_vertices.mem(), skin_weights.mem(), joints.mem(), skins.mem()};
      for (cl_uint a = 0; a < 5; ++a) check(clSetKernelArg(skin_positions, a, sizeof(cl_mem), &position_args[a]), "clSetKernelArg");
      check(clSetKernelArg(skin_positions, 5, sizeof skin_index, &skin_index), "clSetKernelArg");
      check(clEnqueueNDRangeKernel(queue, skin_positions, 1, nullptr, &global, &local, 0, nullptr, nullptr),
            "launching the skinning kernel");
      const cl_mem face_args[] = {vertices.mem(), skin_triangles.mem(), skin_faces.mem(), skins.mem()};
      for (cl_uint a = 0; a < 4; ++a) check(clSetKernelArg(skin_faces_kernel, a, sizeof(cl_mem), &face_args[a]), "clSetKernelArg");
      check(clSetKernelArg(skin_faces_kernel, 4, sizeof skin_index, &skin_index), "clSetKernelArg");
      const size_t face_global = (size_t(skin.triangle_count) + local - 1) / local * local;
      if (face_global > 0)
        check(clEnqueueNDRangeKernel(queue, skin_faces_kernel, 1, nullptr, &face_global, &local, 0, nullptr, nullptr),
              "launching the skinned-faces kernel");
      const cl_mem normal_args[] = {vertices.mem(), skin_vertices.mem(), skin_adjacency.mem(), skin_triangles.mem(),
                                    skin_faces.mem(), skins.mem()};
      for (cl_uint a = 0; a < 6; ++a) check(clSetKernelArg(skin_normals, a, sizeof(cl_mem), &normal_args[a]), "clSetKernelArg");
      check(clSetKernelArg(skin_normals, 6, sizeof skin_index, &skin_index), "clSetKernelArg");
      check(clEnqueueNDRangeKernel(queue, skin_normals, 1, nullptr, &global, &local, 0, nullptr, nullptr),
            "launching the skinned-normals kernel");
      const cl_mem refit_args[] = {blas_nodes.mem(), triangles.mem(), vertices.mem(), blases.mem(), skins.mem()};
      for (cl_kernel k : {refit_leaves, refit_blas}) {
        for (cl_uint a = 0; a < 5; ++a) check(clSetKernelArg(k, a, sizeof(cl_mem), &refit_args[a]), "clSetKernelArg");
        check(clSetKernelArg(k, 5, sizeof skin_index, &skin_index), "clSetKernelArg");
      }
      const uint32_t node_count = skin.blas < s.blases.size() ? s.blases[skin.blas].node_count : 0u;
      const size_t leaf_global = (size_t(node_count) + local - 1) / local * local;
      if (leaf_global > 0)
        check(clEnqueueNDRangeKernel(queue, refit_leaves, 1, nullptr, &leaf_global, &local, 0, nullptr, nullptr),
              "launching the BLAS leaf refit kernel");
      const size_t one = 1;
      check(clEnqueueNDRangeKernel(queue, refit_blas, 1, nullptr, &one, &one, 0, nullptr, nullptr),
            "launching the BLAS refit kernel");
    }
  }
  cl_mem params = nullptr, camera = nullptr, previous_camera = nullptr, output = nullptr, row_rays = nullptr,
         aux = nullptr;
  size_t output_bytes = 0, row_rays_rows = 0, aux_bytes = 0;
  // The band and aux records as they cross the bus (converted on the device, read into the band buffer).
  cl_kernel to_rgb16f = nullptr, to_rgb9e5 = nullptr, to_texels = nullptr;
  cl_mem packed = nullptr, packed_aux = nullptr;
  size_t packed_bytes = 0, packed_aux_bytes = 0;

  // Options::transfer_queue on this device (with enqueue ahead): a band's uploads on `upload_queue`, its reads on
  // `read_queue` behind its last kernel, so `queue` holds only kernels and goes from one band's to the next's.
  // The buffers a band's edges write or read (params, camera, output, row_rays, packed above) are the current
  // slot; `spare` is the other, the band before's, whose reads may still run while the next band renders
  // into this one. Every band with rows takes the other slot (take_other_slot); the band before that one is
  // done by then (its job waited for its last read, or a throw drained every queue).
  bool transfer = false;
  cl_command_queue upload_queue = nullptr, read_queue = nullptr;
  struct Slot {
    cl_mem params = nullptr, camera = nullptr, output = nullptr, row_rays = nullptr, packed = nullptr;
    size_t output_bytes = 0, row_rays_rows = 0, packed_bytes = 0;
  } spare;
  // Options::pinned_band_reads (with `transfer`): the band's colour read into band_staging[band_slot], the
  // slot's own, so a band's read never lands where the band before's copy out of it may still run.
  bool pinned_reads = false;
  bool late_job_cost = false;  // Options::late_job_cost (with `transfer`)
  PinnedStaging band_staging[2];
  int band_slot = 0;
  std::atomic<size_t> staged_reads{0};
  void take_other_slot() {
    band_slot ^= 1;
    std::swap(params, spare.params);
    std::swap(camera, spare.camera);
    std::swap(output, spare.output);
    std::swap(row_rays, spare.row_rays);
    std::swap(packed, spare.packed);
    std::swap(output_bytes, spare.output_bytes);
    std::swap(row_rays_rows, spare.row_rays_rows);
    std::swap(packed_bytes, spare.packed_bytes);
  }
  // The end of the previous band's last kernel on the device clock (0: unknown), for the next band's gap.
  cl_ulong previous_kernels_end = 0;
  // K_AUX_PATH_FIRST_HIT: the band kernel that records its paths' first hits, and the records.
  cl_kernel first_hits_kernel = nullptr;
  cl_mem first_hits = nullptr;
  size_t first_hits_bytes = 0;
  // The aux band in flight: its kernel (timed: the band's device time starts there, as on CUDA), the
  // packing the read waits on, the read into `aux_staging`.
  Event aux_kernel_done, aux_packed, aux_read;
  KCamera previous_camera_host{};
  PinnedStaging aux_staging;

  // Enqueueing ahead (Options::enqueue_ahead): the next band, enqueued while the one before rendered, until
  // render_band takes it; whether a commit is being applied ahead (its uploads then staged, not blocking).
  bool enqueue_ahead = true;
  bool applying_ahead = false;
  std::unique_ptr<EnqueuedBand> ahead;
  std::atomic<size_t> enqueued_ahead{0}, finished_ahead{0}, dropped_ahead{0}, back_to_back{0};
  // Every queue a band's commands go on.
  BandQueues queues() const { return {queue, aux_queue, lane_queue, upload_queue, read_queue}; }
  void finish_queues() { finish_all(queues()); }

  // A device buffer of at least `bytes`, reallocated (contents lost) when it is smaller.
  cl_mem& grow(cl_mem& mem, size_t& capacity, size_t bytes, const char* what) {
    return grow_buffer(context, mem, capacity, bytes, what);
  }

  // The wavefront (Options::wavefront, shadow_walk), its walk program built with walk_options the first
  // time a frame renders as one.
  bool wavefront_on = true, shadow_walk = true;
  std::string walk_options, main_options;
  std::unique_ptr<OpenCLWavefront> wavefront;
  // The wavefront, its kernels' arguments set for this band, where it renders the frame (k_wavefront_renders);
  // null: the megakernel renders it.
  OpenCLWavefront* wavefront_for(const KFrameParams& params, const OpenCLWavefront::BandArgs& band, size_t pixels,
                                 cl_mem first_hit_records) {
    if (!wavefront_on || !k_wavefront_renders(&params)) return nullptr;
    if (!wavefront) {
      wavefront = std::make_unique<OpenCLWavefront>(context, device, program, walk_options, label);
      spdlog::info("opencl ({}): frames that bounce render as a wavefront (walks built with '{}', the rest with '{}')",
                   label, walk_options, main_options);
    }
    const kuint slots = shadow_walk ? k_shadow_queue_slots(&params, params.light_count, params.emissive_count) : 0u;
    wavefront->prepare(band, pixels, slots, first_hit_records);
    return wavefront.get();
  }
  // The wavefront's second lane (Options::wave_lanes; null: one lane): an in-order queue of its own.
  cl_command_queue lane_queue = nullptr;
  // The band's rows [first_row, first_row + rows): the wavefront's kernels where `wave`, else the
  // megakernel `kernel`, in 8x8 work groups from first_row; started / done: the first and last kernel's events
  // (with lanes, `done` is the join: both lanes' kernels are before it).
  void enqueue_band_rows(cl_kernel kernel, OpenCLWavefront* wave, const KFrameParams& params, size_t width,
                         size_t first_row, size_t rows, Event* started, Event* done) {
    if (wave && lane_queue && wave_lane_count(2, static_cast<unsigned>(rows)) == 2) {
      // Two lanes (cohort/tracers/wave_lanes.h, the CUDA tracer's rule), the second on lane_queue behind
      // everything queued so far, joined back before what follows the band.
      const size_t split = wave_lane_first_row(static_cast<unsigned>(rows), 2, 1);
      Event forked, second_done;
      check(clEnqueueMarkerWithWaitList(queue, 0, nullptr, forked.out()), "forking the wavefront's lanes");
      cl_event fork = forked.get();
      check(clEnqueueMarkerWithWaitList(lane_queue, 1, &fork, nullptr), "forking the wavefront's lanes");
      wave->enqueue(queue, params, width, first_row, split, started ? started->out() : nullptr, nullptr);
      wave->enqueue(lane_queue, params, width, first_row + split, rows - split, nullptr, second_done.out());
      check(clFlush(lane_queue), "clFlush(lane)");
      cl_event join = second_done.get();
      check(clEnqueueMarkerWithWaitList(queue, 1, &join, done ? done->out() : nullptr), "joining the wavefront's lanes");
      return;
    }
    if (wave) {
      wave->enqueue(queue, params, width, first_row, rows, started ? started->out() : nullptr,
                    done ? done->out() : nullptr);
      return;
    }
    const size_t local[2] = {8, 8};
    const size_t offset[2] = {0, first_row};
    const size_t global[2] = {(width + 7) / 8 * 8, (rows + 7) / 8 * 8};
    // One kernel: its event is both.
    Event* event = done ? done : started;
    check(clEnqueueNDRangeKernel(queue, kernel, 2, offset, global, local, 0, nullptr, event ? event->out() : nullptr),
          "launching the kernel");
    if (started && done) started->share(*done);
  }
  // Runs a 1-D packing kernel (source, destination, end pixel) over the pixels [first, first + pixels):
  // the kernel stops at the end pixel, so a piece's last work group leaves the next piece's pixels alone.
  void pack(cl_kernel k, cl_mem from, cl_mem to, size_t first, size_t pixels, const char* what,
            cl_event* done = nullptr) {
    const cl_uint end = static_cast<cl_uint>(first + pixels);
    check(clSetKernelArg(k, 0, sizeof(cl_mem), &from), what);
    check(clSetKernelArg(k, 1, sizeof(cl_mem), &to), what);
    check(clSetKernelArg(k, 2, sizeof end, &end), what);
    const size_t local = 64, global = (pixels + local - 1) / local * local;
    check(clEnqueueNDRangeKernel(queue, k, 1, &first, &global, &local, 0, nullptr, done), what);
  }
  // The float band's pixels [first, first + pixels) packed into `to` in `format` (RGB16F or RGB9E5, whose
  // dither takes the pixel's place in the frame: the band starts at frame pixel `band_first_pixel`).
  void pack_colour(core::BandFormat format, cl_mem to, size_t first, size_t pixels, size_t band_first_pixel, cl_uint frame,
                   cl_event* done = nullptr) {
    if (format == core::BandFormat::rgb16f)
      return pack(to_rgb16f, output, to, first, pixels, "converting the band to half floats", done);
    const cl_uint band_first = static_cast<cl_uint>(band_first_pixel);
    check(clSetKernelArg(to_rgb9e5, 3, sizeof band_first, &band_first), "setting the RGB9E5 band's first pixel");
    check(clSetKernelArg(to_rgb9e5, 4, sizeof frame, &frame), "setting the RGB9E5 band's frame");
    pack(to_rgb9e5, output, to, first, pixels, "converting the band to RGB9E5", done);
  }
  // Once `read` is done, the aux planes of `rows` band rows from page-locked staging into the target from
  // `first_row` on: packed texels copied on the aux copy threads (`straight`), else full records
  // converted row by row.
  void copy_aux_rows_into(core::BandBuffer& target, int first_row, size_t width, size_t rows, const void* staging,
                          bool straight, cl_event read) {
    check(clWaitForEvents(1, &read), "waiting for the aux band");
    const size_t pixels = rows * width;
    if (straight) {
      const auto started = std::chrono::steady_clock::now();
      char* to = reinterpret_cast<char*>(target.aux_row(first_row));
      const char* from = static_cast<const char*>(staging);
      aux_copy_threads.for_ranges(pixels, 16384, [&](size_t begin, size_t end) {
        std::memcpy(to + begin * sizeof(KAuxTexel), from + begin * sizeof(KAuxTexel), (end - begin) * sizeof(KAuxTexel));
      });
      const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - started).count();
      spdlog::debug("opencl ({}): aux texels of {} pixels copied in {:.2f} ms", label, pixels, ms);
      return;
    }
    const KAux* aux = static_cast<const KAux*>(staging);
    for (size_t r = 0; r < rows; ++r) target.store_aux(first_row + static_cast<int>(r), 0, aux + r * width, width);
  }

  ~Impl() {
    // A band enqueued ahead may still read into its target: done before anything goes.
    finish_queues();
    ahead.reset();
    wavefront.reset();
    aux_staging.reset();
    for (PinnedStaging& staging : band_staging) staging.reset();
    for (cl_mem m : {params, camera, previous_camera, output, row_rays, aux, packed, packed_aux, first_hits, spare.params,
                     spare.camera, spare.output, spare.row_rays, spare.packed})
      if (m) clReleaseMemObject(m);
    for (cl_kernel k : {kernel, first_hits_kernel, aux_kernel, skin_positions, skin_faces_kernel, skin_normals, refit_leaves, refit_blas,
                        to_rgb16f, to_rgb9e5, to_texels})
      if (k) clReleaseKernel(k);
    if (program) clReleaseProgram(program);
    if (aux_queue) clReleaseCommandQueue(aux_queue);
    if (lane_queue) clReleaseCommandQueue(lane_queue);
    if (upload_queue) clReleaseCommandQueue(upload_queue);
    if (read_queue) clReleaseCommandQueue(read_queue);
    if (queue) clReleaseCommandQueue(queue);
    if (context) clReleaseContext(context);
  }
};

std::vector<std::string> OpenCLTracer::list_devices() {
  std::vector<std::string> out;
  for (const DeviceEntry& d : all_devices()) out.push_back(d.label);
  return out;
}

std::vector<OpenCLTracer::DeviceDescription> OpenCLTracer::describe_devices() {
  std::vector<DeviceDescription> out;
  for (const DeviceEntry& d : all_devices()) {
    DeviceDescription description;
    description.label = d.label;
    cl_device_type type = 0;
    if (clGetDeviceInfo(d.device, CL_DEVICE_TYPE, sizeof(type), &type, nullptr) == CL_SUCCESS)
      description.kind = (type & CL_DEVICE_TYPE_GPU) ? DeviceKind::gpu : (type & CL_DEVICE_TYPE_CPU) ? DeviceKind::cpu : DeviceKind::other;
    description.pci = pci_bus_id(d.device);
    out.push_back(description);
  }
  return out;
}

OpenCLTracer::OpenCLTracer(const Options& options) : impl_(std::make_unique<Impl>()) {
  if (options.first_hit_pieces < 1 || options.first_hit_pieces > kMaxFirstHitPieces)
    throw std::invalid_argument("OpenCLTracer: first_hit_pieces " + std::to_string(options.first_hit_pieces) +
                                " is outside 1-" + std::to_string(kMaxFirstHitPieces));
  impl_->first_hit_pieces = options.first_hit_pieces;
  impl_->aux_into_target = options.aux_into_target;
  impl_->enqueue_ahead = options.enqueue_ahead;
  std::vector<DeviceEntry> devices = all_devices();
  if (devices.empty()) throw std::runtime_error("OpenCLTracer: no OpenCL platform/device found");
  if (options.device < 0 || static_cast<size_t>(options.device) >= devices.size())
    throw std::runtime_error("OpenCLTracer: device " + std::to_string(options.device) + " requested, " +
                             std::to_string(devices.size()) + " available");
  const DeviceEntry& dev = devices[static_cast<size_t>(options.device)];
  impl_->label = dev.label;
  cl_device_type type = 0;
  impl_->gpu = clGetDeviceInfo(dev.device, CL_DEVICE_TYPE, sizeof(type), &type, nullptr) == CL_SUCCESS &&
               (type & CL_DEVICE_TYPE_GPU) != 0;
  cl_int err = CL_SUCCESS;
  cl_context_properties props[] = {CL_CONTEXT_PLATFORM, reinterpret_cast<cl_context_properties>(dev.platform), 0};
  impl_->context = clCreateContext(props, 1, &dev.device, nullptr, nullptr, &err);
  check(err, "clCreateContext");
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wdeprecated-declarations"
#endif
  impl_->queue = clCreateCommandQueue(impl_->context, dev.device, CL_QUEUE_PROFILING_ENABLE, &err);
  check(err, "clCreateCommandQueue");
  impl_->aux_queue = clCreateCommandQueue(impl_->context, dev.device, 0, &err);
  check(err, "clCreateCommandQueue(aux)");

#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif
  // NVIDIA's compiler takes a register cap per program (cl_nv_compiler_options): the walks'
  // (Options::walk_registers) and the main program's (Options::shade_registers: shading kernels and
  // megakernels); other platforms know no such option.
  const bool nvidia = lists_extension(device_info(dev.device, CL_DEVICE_EXTENSIONS), "cl_nv_compiler_options") ||
                      device_info(dev.device, CL_DEVICE_VENDOR).find("NVIDIA") != std::string::npos;
  auto with_registers = [&](int registers) {
    std::string o = "-cl-std=CL1.2 " + options.build_options;
    if (nvidia && registers > 0) o += " -cl-nv-maxrregcount=" + std::to_string(registers);
    return o;
  };
  impl_->device = dev.device;
  impl_->transfer = options.enqueue_ahead && (options.transfer_queue == Options::TransferQueue::always ||
                                              (options.transfer_queue == Options::TransferQueue::on_gpus && impl_->gpu));
  impl_->pinned_reads = impl_->transfer && options.pinned_band_reads;
  impl_->late_job_cost = impl_->transfer && options.late_job_cost;
  if (impl_->transfer) {
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wdeprecated-declarations"
#endif
    impl_->upload_queue = clCreateCommandQueue(impl_->context, dev.device, 0, &err);
    check(err, "clCreateCommandQueue(upload)");
    // Profiled: the band's read times its way back (finish_band).
    impl_->read_queue = clCreateCommandQueue(impl_->context, dev.device, CL_QUEUE_PROFILING_ENABLE, &err);
    check(err, "clCreateCommandQueue(read)");
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif
  }
  impl_->wavefront_on = options.wavefront == Options::Wavefront::always ||
                        (options.wavefront == Options::Wavefront::on_gpus && impl_->gpu);
  impl_->shadow_walk = options.shadow_walk;
  if (options.wave_lanes && impl_->gpu) {
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wdeprecated-declarations"
#endif
    impl_->lane_queue = clCreateCommandQueue(impl_->context, dev.device, 0, &err);
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif
    check(err, "clCreateCommandQueue(lane)");
  }
  impl_->walk_options = with_registers(options.walk_registers);
  impl_->main_options = with_registers(options.shade_registers);
  impl_->program = build_program(impl_->context, dev.device, opencl_source::kRenderBand, "render_band",
                                 impl_->main_options, dev.label);
  impl_->kernel = clCreateKernel(impl_->program, "cohort_render_band", &err);
  check(err, "clCreateKernel");
  impl_->skin_positions = clCreateKernel(impl_->program, "cohort_skin_positions", &err);
  check(err, "clCreateKernel(cohort_skin_positions)");
  impl_->skin_faces_kernel = clCreateKernel(impl_->program, "cohort_skin_faces", &err);
  check(err, "clCreateKernel(cohort_skin_faces)");
  impl_->skin_normals = clCreateKernel(impl_->program, "cohort_skin_normals", &err);
  check(err, "clCreateKernel(cohort_skin_normals)");
  impl_->refit_leaves = clCreateKernel(impl_->program, "cohort_refit_blas_leaves", &err);
  check(err, "clCreateKernel(cohort_refit_blas_leaves)");
  impl_->refit_blas = clCreateKernel(impl_->program, "cohort_refit_blas", &err);
  check(err, "clCreateKernel(cohort_refit_blas)");
  impl_->first_hits_kernel = clCreateKernel(impl_->program, "cohort_render_band_first_hits", &err);
  check(err, "clCreateKernel(cohort_render_band_first_hits)");
  impl_->aux_kernel = clCreateKernel(impl_->program, "cohort_aux_band", &err);
  check(err, "clCreateKernel(aux)");
  impl_->to_rgb16f = clCreateKernel(impl_->program, "cohort_band_to_rgb16f", &err);
  check(err, "clCreateKernel(cohort_band_to_rgb16f)");
  impl_->to_rgb9e5 = clCreateKernel(impl_->program, "cohort_band_to_rgb9e5", &err);
  check(err, "clCreateKernel(cohort_band_to_rgb9e5)");
  impl_->to_texels = clCreateKernel(impl_->program, "cohort_aux_to_texels", &err);
  check(err, "clCreateKernel(cohort_aux_to_texels)");
  impl_->previous_camera = clCreateBuffer(impl_->context, CL_MEM_READ_ONLY, sizeof(KCamera), nullptr, &err);
  check(err, "clCreateBuffer(previous camera)");
  impl_->params = clCreateBuffer(impl_->context, CL_MEM_READ_ONLY, sizeof(KFrameParams), nullptr, &err);
  check(err, "clCreateBuffer(params)");
  impl_->camera = clCreateBuffer(impl_->context, CL_MEM_READ_ONLY, sizeof(KCamera), nullptr, &err);
  check(err, "clCreateBuffer(camera)");
  if (impl_->transfer) {
    impl_->spare.params = clCreateBuffer(impl_->context, CL_MEM_READ_ONLY, sizeof(KFrameParams), nullptr, &err);
    check(err, "clCreateBuffer(params)");
    impl_->spare.camera = clCreateBuffer(impl_->context, CL_MEM_READ_ONLY, sizeof(KCamera), nullptr, &err);
    check(err, "clCreateBuffer(camera)");
  }
}

OpenCLTracer::~OpenCLTracer() = default;

std::string OpenCLTracer::name() const { return "opencl (" + impl_->label + ")"; }

bool OpenCLTracer::renders_on_gpu() const { return impl_->gpu; }
bool OpenCLTracer::wavefront() const { return impl_->wavefront_on; }
bool OpenCLTracer::shadow_walk() const { return impl_->shadow_walk; }

void OpenCLTracer::upload(const commit::ChangeSet& changes) {
  Impl& m = *impl_;
  const commit::TracerScene& s = scene();
  const bool all = changes.full_resync;
  cl_context c = m.context;
  cl_command_queue q = m.queue;
  // Applied ahead (enqueue_next_ahead), the band before is still in the queue: written without blocking, from
  // copies (the in-order queue runs the writes after that band's kernels).
  const bool staged = m.applying_ahead;
  auto up = [&](DeviceBuffer& buffer, const auto& data, const char* what) { buffer.upload(c, q, data, what, CL_TRUE, staged); };
  if (all || changes.geometry) {
    up(m.vertices, s.vertices, "uploading vertices");
    up(m.vertex_colors, s.vertex_colors, "uploading vertex colours");
    up(m.triangles, s.triangles, "uploading triangles");
    up(m.blas_nodes, s.blas_nodes, "uploading BLAS nodes");
    up(m.blases, s.blases, "uploading BLASes");
  }
  if (all || changes.instances || changes.tlas) {
    up(m.instances, s.instances, "uploading instances");
    up(m.tlas_nodes, s.tlas_nodes, "uploading TLAS nodes");
  }
  if (all || changes.materials) up(m.materials, s.materials, "uploading materials");
  if (all || changes.textures) {
    up(m.textures, s.textures, "uploading textures");
    up(m.texels, s.texels, "uploading texels");
  }
  if (all || changes.lights) up(m.lights, s.lights, "uploading lights");
  if (all || changes.light_tree) up(m.light_nodes, s.light_nodes, "uploading the light tree");
  if (all || changes.emissive) up(m.emissive, s.emissive_triangles, "uploading emissive triangles");
  if (all || changes.skin_data) {
    up(m.skins, s.skins, "uploading skins");
    up(m.skin_vertices, s.skin_vertices, "uploading skin vertices");
    up(m.skin_weights, s.skin_weights, "uploading skin weights");
    up(m.skin_triangles, s.skin_triangles, "uploading skin triangles");
    up(m.skin_adjacency, s.skin_adjacency, "uploading skin adjacency");
    up(m.skin_faces, s.skin_faces, "sizing the skin faces");   // the kernels write them
  }
  if (all || !changes.posed_skins.empty()) up(m.joints, s.joints, "uploading joints");
  // Vertices just uploaded from the host copy are not posed there (the host keeps only the joints), so
  // every skin runs again after a geometry upload; otherwise only the skins whose joints changed.
  if (all || changes.geometry) {
    std::vector<uint32_t> every(s.skins.size());
    for (size_t i = 0; i < every.size(); ++i) every[i] = uint32_t(i);
    m.run_skinning(s, every);
  } else {
    m.run_skinning(s, changes.posed_skins);
  }
}

namespace {

// The band kernels' work groups are 8x8 pixels (render_band.cl sums a group's rays per row in local memory).
constexpr size_t kGroupRows = 8;

// Every queue of a band drained however the function that declares it leaves (a failed check throws):
// declared after the host memory the queues read into, it runs before that memory goes.
struct FinishQueues {
  BandQueues queues;
  ~FinishQueues() { finish_all(queues); }
};

}  // namespace

std::vector<size_t> OpenCLTracer::piece_starts(size_t rows, int pieces, size_t group_rows) {
  std::vector<size_t> starts{0};
  if (rows == 0) return starts;
  const size_t count = static_cast<size_t>(std::clamp(pieces, 1, kMaxFirstHitPieces));
  const size_t groups = std::max<size_t>(group_rows, 1);
  const size_t per_piece = ((rows + count - 1) / count + groups - 1) / groups * groups;
  for (size_t start = per_piece; start < rows; start += per_piece) starts.push_back(start);
  starts.push_back(rows);
  return starts;
}

namespace {

// On a throw, every queue drained before the host memory its commands use goes: declared after that memory.
struct DrainOnThrow {
  BandQueues queues;
  int exceptions = std::uncaught_exceptions();
  ~DrainOnThrow() {
    if (std::uncaught_exceptions() > exceptions) finish_all(queues);
  }
};

// The OpenCL runtime's completion callback on a band's last command.
void CL_CALLBACK band_completed(cl_event, cl_int, void* user) { BandSignal::fire_and_release(user); }

bool event_ended(cl_event event) {
  cl_int status = CL_COMPLETE;
  if (clGetEventInfo(event, CL_EVENT_COMMAND_EXECUTION_STATUS, sizeof status, &status, nullptr) != CL_SUCCESS) return true;
  return status <= CL_COMPLETE;  // complete, or failed (negative)
}


}  // namespace

core::BandResult OpenCLTracer::render_band(const core::BandJob& job, core::BandBuffer& target) {
  Impl& m = *impl_;
  if (!has_scene()) throw std::runtime_error("OpenCLTracer: render_band before any commit was applied");
  using Clock = std::chrono::steady_clock;
  const auto entry = Clock::now();
  std::unique_ptr<EnqueuedBand> band;
  // A throw from here on (the aux copy, the wait, the next band's enqueueing) drains every queue before the
  // band's memory goes; the band enqueued ahead, if any, stays for its job.
  DrainOnThrow drain{m.queues()};
  if (m.ahead) {
    if (m.ahead->target == &target && same_band_job(m.ahead->job, job)) {
      band = std::move(m.ahead);
      ++m.finished_ahead;
    } else {
      spdlog::debug("opencl ({}): the band enqueued ahead is not this job's; drained, and this one enqueued now",
                    m.label);
      drop_enqueued_ahead();
    }
  }
  if (!band) {
    band = enqueue_band(job, target, false);
    if (band->rows == 0) return {};
    if (band->aux_from_paths)
      return render_first_hits_in_pieces(job, target, band->params, band->camera, band->straight, band->wave);
  }
  // The host's share of the aux planes (out of page-locked memory into the target) while the band renders;
  // done before the next band is enqueued, whose aux texels are read into the same staging.
  if (band->write_aux)
    m.copy_aux_rows_into(target, int(band->params.row_begin), band->camera.width, band->rows, m.aux_staging.host(),
                         band->straight, band->aux_read.get());
  // The host's time from this job's start until its band is all in the queue: the whole enqueueing, or
  // nothing where it was enqueued ahead.
  const auto queued = Clock::now();
  enqueue_next_ahead(*band);
  const auto waiting = Clock::now();
  core::BandResult result = finish_band(*band);
  if (m.late_job_cost && !band->ahead && m.enqueued_ahead.load() > 0)
    result.balance_ms = std::max(
        1e-3, std::chrono::duration<double, std::milli>(Clock::now() - entry).count() - band->enqueue_ms);
  if (spdlog::should_log(spdlog::level::debug)) {
    const auto ms = [](Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double, std::milli>(b - a).count(); };
    spdlog::debug("opencl ({}): band [{}, {}) of frame {}: {} in {:.3f} ms; {:.3f} ms before it was all in the queue, "
                  "{:.3f} ms on the next band ahead ({}), {:.3f} ms waiting; device gap after the band before {:.3f} ms, "
                  "kernels {:.3f} ms, transfer {:.3f} ms",
                  m.label, band->params.row_begin, band->params.row_end, band->params.frame_index,
                  band->ahead ? "enqueued ahead" : "enqueued", band->enqueue_ms, ms(entry, queued), ms(queued, waiting),
                  m.ahead ? "enqueued" : "none", ms(waiting, Clock::now()), band->gap_ms, result.device_ms,
                  result.transfer_ms);
  }
  return result;
}

std::unique_ptr<OpenCLTracer::EnqueuedBand> OpenCLTracer::enqueue_band(const core::BandJob& job,
                                                                      core::BandBuffer& target, bool ahead) {
  Impl& m = *impl_;
  const auto started = std::chrono::steady_clock::now();
  auto b = std::make_unique<EnqueuedBand>();
  b->job = job;
  b->target = &target;
  KFrameParams& params = b->params;
  KCamera& camera = b->camera;
  params = frame_params(job);
  camera = job.camera;
  params.row_end = std::min<kuint>(params.row_end, static_cast<kuint>(target.height()));
  camera.width = std::min<kuint>(camera.width, static_cast<kuint>(target.width()));
  if (params.row_end <= params.row_begin || camera.width == 0) return b;
  b->whole_band = params.row_end == frame_params(job).row_end;
  const size_t rows = params.row_end - params.row_begin;
  const size_t bytes = rows * camera.width * 4 * sizeof(float);
  // The other slot's buffers: the band before (maybe still in the queues) keeps its own.
  if (m.transfer) m.take_other_slot();
  // Grown buffers are released under the band before still in the queue: OpenCL keeps a memory object until
  // the commands that use it are done.
  cl_int err = CL_SUCCESS;
  if (bytes > m.output_bytes) {
    if (m.output) clReleaseMemObject(m.output);
    m.output = clCreateBuffer(m.context, CL_MEM_WRITE_ONLY, bytes, nullptr, &err);
    check(err, "clCreateBuffer(output)");
    m.output_bytes = bytes;
  }
  if (rows > m.row_rays_rows) {
    if (m.row_rays) clReleaseMemObject(m.row_rays);
    m.row_rays = clCreateBuffer(m.context, CL_MEM_READ_WRITE, rows * sizeof(cl_uint), nullptr, &err);
    check(err, "clCreateBuffer(row rays)");
    m.row_rays_rows = rows;
  }
  b->row_rays.resize(rows);
  // The reads and writes below run from and into the band's own memory without blocking: on a throw every
  // queue is done before it goes (the guard goes after it).
  DrainOnThrow drain{m.queues()};
  const cl_uint zero = 0;
  // Enqueued ahead with the transfer queues, these run on the upload queue as soon as they are enqueued (into
  // this band's slot, which nothing in any queue uses), while the band before renders; the compute queue waits
  // for them with a barrier that is long done when it comes to it. Otherwise they run in the compute queue's
  // order (a band enqueued when its job starts finds every queue empty: nothing to overlap).
  const bool upload_aside = m.transfer && ahead;
  cl_command_queue upload = upload_aside ? m.upload_queue : m.queue;
  Event uploaded;
  check(clEnqueueFillBuffer(upload, m.row_rays, &zero, sizeof zero, 0, rows * sizeof(cl_uint), 0, nullptr, nullptr),
        "clearing the row ray counts");
  check(clEnqueueWriteBuffer(upload, m.params, CL_FALSE, 0, sizeof params, &params, 0, nullptr, nullptr),
        "writing frame parameters");
  check(clEnqueueWriteBuffer(upload, m.camera, CL_FALSE, 0, sizeof camera, &camera, 0, nullptr,
                             upload_aside ? uploaded.out() : nullptr),
        "writing the camera");
  if (upload_aside) {
    check(clFlush(m.upload_queue), "clFlush(upload)");
    const cl_event written = uploaded.get();  // the last of the three, in the upload queue's order
    check(clEnqueueBarrierWithWaitList(m.queue, 1, &written, nullptr), "waiting for the band's uploads");
  }
  // Only frames that ask pay for the aux planes. From centre rays: a short kernel before the band's, whose
  // texels go down on the second queue while the band's kernel runs (the CUDA tracer's order); from the
  // paths' first hits: the band's kernel records them and the aux kernel finishes them after it, piece by
  // piece (render_first_hits_in_pieces).
  const bool write_aux = params.aux_outputs != 0u && target.has_aux();
  const bool aux_from_paths = write_aux && k_aux_from_paths(&params);
  const bool straight = target.width() == static_cast<int>(camera.width);
  b->rows = rows;
  b->straight = straight;
  b->write_aux = write_aux;
  b->aux_from_paths = aux_from_paths;
  cl_mem args[] = {m.vertices.mem(),  m.vertex_colors.mem(), m.triangles.mem(), m.blas_nodes.mem(), m.blases.mem(),
                   m.instances.mem(), m.tlas_nodes.mem(), m.materials.mem(), m.textures.mem(),
                   m.texels.mem(),    m.lights.mem(),     m.light_nodes.mem(), m.emissive.mem(),
                   m.params,          m.camera,           m.output,           m.row_rays};
  cl_kernel band_kernel = aux_from_paths ? m.first_hits_kernel : m.kernel;
  cl_uint arg_count = sizeof(args) / sizeof(args[0]);
  for (cl_uint i = 0; i < arg_count; ++i)
    check(clSetKernelArg(band_kernel, i, sizeof(cl_mem), &args[i]), "clSetKernelArg");
  cl_mem records = nullptr;
  if (aux_from_paths) {
    records = m.grow(m.first_hits, m.first_hits_bytes, rows * camera.width * sizeof(KPathFirstHit),
                     "clCreateBuffer(first hits)");
    check(clSetKernelArg(band_kernel, arg_count, sizeof(cl_mem), &records), "clSetKernelArg(first hits)");
  }
  OpenCLWavefront::BandArgs band_args;
  std::copy(std::begin(args), std::end(args), band_args.begin());
  b->wave = m.wavefront_for(params, band_args, rows * camera.width, records);
  if (aux_from_paths) return b;  // the rest in pieces, in render_first_hits_in_pieces
  if (write_aux) enqueue_aux(job, camera, rows, straight);
  m.enqueue_band_rows(band_kernel, b->wave, params, camera.width, 0, rows, &b->band_started, &b->band_done);
  // The band goes straight into its rows of the target, converted on the device to the target's format.
  const size_t pixels = rows * camera.width;
  size_t band_bytes = bytes;
  cl_mem band_mem = m.output;
  if (!straight) {
    b->band.resize(pixels * 4);
  } else if (target.format() != core::BandFormat::rgba32f) {
    band_bytes = pixels * core::bytes_per_pixel(target.format());
    band_mem = m.grow(m.packed, m.packed_bytes, band_bytes, "clCreateBuffer(packed band)");
    m.pack_colour(target.format(), band_mem, 0, pixels, size_t(params.row_begin) * camera.width, params.frame_index,
                  b->kernels_done.out());
  }
  if (!b->kernels_done.get()) {
    b->kernels_done.share(b->band_done);
  }
  // Both kernels are on the device before any read is enqueued: a driver that copies into pageable
  // memory at enqueue time then still overlaps the aux read with the band's kernel.
  check(clFlush(m.queue), "clFlush");
  if (write_aux) {
    read_aux_when_packed(rows * camera.width, straight);
    b->aux_kernel_done.take(m.aux_kernel_done);
    b->aux_read.take(m.aux_read);
  }
  void* band_destination = straight ? target.row(int(params.row_begin)) : b->band.data();
  if (m.transfer) {
    // The reads on the read queue behind the band's last kernel, so that the compute queue goes on to the next
    // band's kernels at once (its buffers are the other slot's). The row counts (a few KB) first and the band
    // last: its read's end is the band's (`last`), so a read held back shows in its transfer time. (On PoCL
    // the second of two reads started only after the next band's kernels, 50 ms late, where they were the
    // other way round.)
    void* row_rays_destination = b->row_rays.data();
    if (m.pinned_reads && straight) {
      // The band, then its row counts, in the slot's staging; as large as the whole target's, so that it is
      // mapped once (the map waits for the upload queue).
      const size_t most = std::max(band_bytes, size_t(target.height()) * target.row_bytes());
      char* staging = static_cast<char*>(m.band_staging[m.band_slot].reserve(
          m.context, m.upload_queue, most + size_t(target.height()) * sizeof(cl_uint), "allocating page-locked band memory"));
      band_destination = staging;
      row_rays_destination = staging + most;
      b->staged = staging;
      b->staged_bytes = band_bytes;
      b->staged_row_rays = row_rays_destination;
    }
    const cl_event kernels_done = b->kernels_done.get();
    check(clEnqueueReadBuffer(m.read_queue, m.row_rays, CL_FALSE, 0, rows * sizeof(cl_uint), row_rays_destination, 1,
                              &kernels_done, nullptr),
          "reading the row ray counts");
    check(clEnqueueReadBuffer(m.read_queue, band_mem, CL_FALSE, 0, band_bytes, band_destination, 0, nullptr,
                              b->band_read.out()),
          "reading the band");
    b->last.share(b->band_read);
    check(clFlush(m.read_queue), "clFlush(read)");
  } else {
    check(clEnqueueReadBuffer(m.queue, band_mem, CL_FALSE, 0, band_bytes, band_destination, 0, nullptr, b->band_read.out()),
          "reading the band");
    check(clEnqueueReadBuffer(m.queue, m.row_rays, CL_FALSE, 0, rows * sizeof(cl_uint), b->row_rays.data(), 0, nullptr,
                              b->last.out()),
          "reading the row ray counts");
    check(clFlush(m.queue), "clFlush");
  }
  b->enqueue_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - started).count();
  return b;
}

void OpenCLTracer::enqueue_next_ahead(const EnqueuedBand& current) {
  Impl& m = *impl_;
  if (!m.enqueue_ahead || m.ahead) return;
  // The worker waits for the next job until the current band's last command is done: the runtime's callback
  // wakes it then (it also looks at the event's status every millisecond).
  const cl_event last = current.last.get();
  auto signal = std::make_shared<BandSignal>();
  signal->tracer = this;
  void* user = BandSignal::callback_argument(signal);
  if (clSetEventCallback(last, CL_COMPLETE, band_completed, user) != CL_SUCCESS) BandSignal::release(user);
  const DisarmOnExit disarm{*signal};
  const BandDone band_done = [&] { return signal->done.load() || event_ended(last); };
  // The next job's commit is applied inside queued_next, on this thread: its uploads staged, not blocking.
  std::optional<QueuedNext> next;
  {
    const FlagForScope applying(m.applying_ahead);
    next = queued_next(band_done);
  }
  if (!next) return;
  if (next->job.params.aux_outputs != 0u && next->target->has_aux() && k_aux_from_paths(&next->job.params)) {
    // Its aux planes from its paths' first hits come in pieces whose host copies interleave with the waits
    // (render_first_hits_in_pieces): it is enqueued when its job starts. (Centre rays go ahead: this band's
    // aux texels are out of the page-locked staging by now, and its aux read done.)
    spdlog::debug("opencl ({}): the next band's aux planes come from its paths' first hits; not enqueued ahead", m.label);
    return;
  }
  try {
    std::unique_ptr<EnqueuedBand> b = enqueue_band(next->job, *next->target, true);
    if (b->rows == 0) return;
    b->ahead = true;
    m.ahead = std::move(b);
    ++m.enqueued_ahead;
    if (m.transfer) ++m.back_to_back;
  } catch (const std::exception& e) {
    // enqueue_band drained the queues: nothing of it is left to write anywhere. Its job enqueues it again.
    spdlog::warn("opencl ({}): enqueueing the next band ahead failed ({}); it is enqueued when its job starts", m.label,
                 e.what());
  }
}

core::BandResult OpenCLTracer::finish_band(EnqueuedBand& b) {
  Impl& m = *impl_;
  const cl_event last = b.last.get();
  check(clWaitForEvents(1, &last), "waiting for the band");
  const KFrameParams& params = b.params;
  const size_t width = b.camera.width;
  if (b.staged) {
    std::memcpy(b.target->row(static_cast<int>(params.row_begin)), b.staged, b.staged_bytes);
    std::memcpy(b.row_rays.data(), b.staged_row_rays, b.rows * sizeof(cl_uint));
    ++m.staged_reads;
  }
  for (size_t r = 0; r < b.rows && !b.straight; ++r)
    b.target->store(static_cast<int>(params.row_begin + r), 0, b.band.data() + r * width * 4, width, params.frame_index);
  // Device time from the first kernel (the aux one when it ran first, as the CUDA tracer times it) to the
  // band's last kernel.
  const cl_ulong start = (b.write_aux ? b.aux_kernel_done : b.band_started).time(CL_PROFILING_COMMAND_START);
  const cl_ulong end = b.band_done.time(CL_PROFILING_COMMAND_END);
  // The device's gap between the band before's last kernel and this band's first (commits applied between
  // them included), for the debug log.
  if (start != 0 && m.previous_kernels_end != 0 && start > m.previous_kernels_end)
    b.gap_ms = double(start - m.previous_kernels_end) * 1e-6;
  m.previous_kernels_end = b.kernels_done.time(CL_PROFILING_COMMAND_END);
  core::BandResult result;
  result.device_ms = end > start && start != 0 ? double(end - start) * 1e-6 : 0.0;
  // The band's way back (the packing to RGB16F or RGB9E5, then the read), as the CUDA tracer reports it.
  const cl_ulong read_end = b.band_read.time(CL_PROFILING_COMMAND_END);
  if (result.device_ms > 0.0 && read_end > end) result.transfer_ms = double(read_end - end) * 1e-6;
  if (b.whole_band) result.row_work.assign(b.row_rays.begin(), b.row_rays.end());
  return result;
}

bool OpenCLTracer::enqueues_ahead() const { return impl_->enqueue_ahead; }

void OpenCLTracer::drop_enqueued_ahead() {
  Impl& m = *impl_;
  if (!m.ahead) return;
  m.finish_queues();
  m.ahead.reset();
  ++m.dropped_ahead;
}

size_t OpenCLTracer::bands_enqueued_ahead() const { return impl_->enqueued_ahead.load(); }
size_t OpenCLTracer::bands_finished_ahead() const { return impl_->finished_ahead.load(); }
size_t OpenCLTracer::bands_dropped_ahead() const { return impl_->dropped_ahead.load(); }
size_t OpenCLTracer::bands_back_to_back() const { return impl_->back_to_back.load(); }
bool OpenCLTracer::transfer_queues() const { return impl_->transfer; }
size_t OpenCLTracer::bands_read_through_staging() const { return impl_->staged_reads.load(); }

core::BandResult OpenCLTracer::render_first_hits_in_pieces(const core::BandJob& job, core::BandBuffer& target,
                                                           const KFrameParams& params, const KCamera& camera,
                                                           bool straight, OpenCLWavefront* wave) {
  Impl& m = *impl_;
  const size_t width = camera.width;
  const size_t rows = params.row_end - params.row_begin;
  const size_t pixels = rows * width;
  const std::vector<size_t> starts = piece_starts(rows, m.first_hit_pieces, kGroupRows);
  const size_t pieces = starts.size() - 1;
  // A band narrower than the target comes down as float pixels and full aux records, stored row by row.
  std::vector<float> band(straight ? 0 : pixels * 4);
  std::vector<cl_uint> row_rays(rows);
  Event band_started;
  std::array<Event, kMaxFirstHitPieces> piece_ready, aux_read, colour_read;
  FinishQueues finish_queues{m.queues()};
  const bool packed = straight && target.format() != core::BandFormat::rgba32f;
  const size_t colour_bytes = packed ? core::bytes_per_pixel(target.format()) : 4 * sizeof(float);
  cl_mem colour = packed ? m.grow(m.packed, m.packed_bytes, pixels * colour_bytes, "clCreateBuffer(packed band)") : m.output;
  const size_t aux_bytes = straight ? sizeof(KAuxTexel) : sizeof(KAux);
  const bool aux_into_target = straight && m.aux_into_target;
  char* staging = aux_into_target ? nullptr
                                  : static_cast<char*>(m.aux_staging.reserve(m.context, m.aux_queue, pixels * aux_bytes,
                                                                             "allocating page-locked aux memory"));
  // The whole band's texels before the first piece: growing them later would lose the earlier pieces'.
  if (straight) m.grow(m.packed_aux, m.packed_aux_bytes, pixels * sizeof(KAuxTexel), "clCreateBuffer(aux texels)");
  prepare_aux(job, camera, rows);
  // Each piece renders, finishes its first hits and packs into its own rows of the band's device buffers,
  // so the second queue reads piece i while the main one runs piece i + 1.
  for (size_t i = 0; i < pieces; ++i) {
    const size_t first = starts[i], count = starts[i + 1] - first;
    m.enqueue_band_rows(m.first_hits_kernel, wave, params, width, first, count, i == 0 ? &band_started : nullptr,
                        nullptr);
    enqueue_aux_rows(camera, first, count, straight);
    if (packed)
      m.pack_colour(target.format(), colour, first * width, count * width, size_t(params.row_begin) * width,
                    params.frame_index);
    check(clEnqueueMarkerWithWaitList(m.queue, 0, nullptr, piece_ready[i].out()), "marking a piece's end");
    check(clFlush(m.queue), "clFlush");
  }
  // Piece by piece: its reads behind its marker (the page-locked aux read never blocks; a driver may hold
  // the colour read into pageable memory until it is done, by when the aux read is too), then the host's
  // copy of its aux rows while the later pieces render.
  for (size_t i = 0; i < pieces; ++i) {
    const size_t first = starts[i], count = starts[i + 1] - first;
    const cl_event ready = piece_ready[i].get();
    void* aux_destination =
        aux_into_target ? static_cast<void*>(target.aux_row(int(params.row_begin + first))) : staging + first * width * aux_bytes;
    check(clEnqueueReadBuffer(m.aux_queue, straight ? m.packed_aux : m.aux, CL_FALSE, first * width * aux_bytes,
                              count * width * aux_bytes, aux_destination, 1, &ready, aux_read[i].out()),
          "reading the aux band");
    void* colour_destination = straight ? target.row(int(params.row_begin + first)) : band.data() + first * width * 4;
    check(clEnqueueReadBuffer(m.aux_queue, colour, CL_FALSE, first * width * colour_bytes, count * width * colour_bytes,
                              colour_destination, 1, &ready, colour_read[i].out()),
          "reading the band");
    check(clFlush(m.aux_queue), "clFlush(aux)");
    if (aux_into_target) continue;  // both reads land in place: the queue is finished below
    m.copy_aux_rows_into(target, int(params.row_begin + first), width, count, staging + first * width * aux_bytes,
                         straight, aux_read[i].get());
    if (straight) continue;
    const cl_event read = colour_read[i].get();
    check(clWaitForEvents(1, &read), "waiting for the band");
    for (size_t r = first; r < first + count; ++r)
      target.store(static_cast<int>(params.row_begin + r), 0, band.data() + r * width * 4, width, params.frame_index);
  }
  // Blocking, and only now: a read into pageable memory may return only once the whole queue got there.
  check(clEnqueueReadBuffer(m.queue, m.row_rays, CL_TRUE, 0, rows * sizeof(cl_uint), row_rays.data(), 0, nullptr, nullptr),
        "reading the row ray counts");
  check(clFinish(m.aux_queue), "waiting for the band's reads");
  // Device time from the first piece's band kernel to the last piece's aux kernel.
  const cl_ulong start = band_started.time(CL_PROFILING_COMMAND_START);
  const cl_ulong end = m.aux_kernel_done.time(CL_PROFILING_COMMAND_END);
  m.previous_kernels_end = 0;  // the next band's gap unknown: this band's reads ran between
  core::BandResult result;
  result.device_ms = end > start && start != 0 ? double(end - start) * 1e-6 : 0.0;
  if (params.row_end == frame_params(job).row_end) result.row_work.assign(row_rays.begin(), row_rays.end());
  return result;
}

void OpenCLTracer::enqueue_aux(const core::BandJob& job, const KCamera& camera, size_t rows, bool straight) {
  prepare_aux(job, camera, rows);
  enqueue_aux_rows(camera, 0, rows, straight);
}

void OpenCLTracer::prepare_aux(const core::BandJob& job, const KCamera& camera, size_t rows) {
  Impl& m = *impl_;
  const size_t bytes = rows * camera.width * sizeof(KAux);
  cl_int err = CL_SUCCESS;
  if (bytes > m.aux_bytes) {
    if (m.aux) clReleaseMemObject(m.aux);
    m.aux = clCreateBuffer(m.context, CL_MEM_READ_WRITE, bytes, nullptr, &err);
    check(err, "clCreateBuffer(aux)");
    m.aux_bytes = bytes;
  }
  // Written without blocking: from the tracer's own copy, which outlives the write (a local would not).
  m.previous_camera_host = job.previous_camera.width > 0 ? job.previous_camera : job.camera;
  check(clEnqueueWriteBuffer(m.queue, m.previous_camera, CL_FALSE, 0, sizeof(KCamera), &m.previous_camera_host, 0,
                             nullptr, nullptr),
        "writing the previous camera");
  // Not blocking: the previous frame's transforms and joints stay as they are until the next commit, and
  // render_band finishes the queue before it returns.
  m.previous_transforms.upload(m.context, m.queue, previous_transforms(), "uploading previous transforms", CL_FALSE);
  m.previous_joints.upload(m.context, m.queue, previous_joints(), "uploading previous joints", CL_FALSE);
  // Skinned motion only where every array it reads is on the device (a scene without skins never sized them).
  const bool skinned = !previous_joints().empty() && m.skins.mem() && m.skin_vertices.mem() && m.skin_weights.mem();
  const cl_uint skin_count = skinned ? static_cast<cl_uint>(scene().skins.size()) : 0u;
  cl_mem skin_args[] = {m.skins.mem(), m.skin_vertices.mem(), m.skin_weights.mem(), m.previous_joints.mem()};
  if (!skinned)
    for (cl_mem& a : skin_args) a = m.previous_transforms.mem();  // never read: any valid buffer
  cl_mem args[] = {m.vertices.mem(),  m.vertex_colors.mem(), m.triangles.mem(),  m.blas_nodes.mem(),  m.blases.mem(),
                   m.instances.mem(), m.tlas_nodes.mem(), m.materials.mem(),   m.textures.mem(),
                   m.texels.mem(),    m.lights.mem(),     m.light_nodes.mem(), m.emissive.mem(),
                   m.params,          m.camera,           m.previous_camera,   m.previous_transforms.mem(),
                   skin_args[0],      skin_args[1],       skin_args[2],        skin_args[3]};
  cl_uint arg = 0;
  for (; arg < sizeof(args) / sizeof(args[0]); ++arg)
    check(clSetKernelArg(m.aux_kernel, arg, sizeof(cl_mem), &args[arg]), "clSetKernelArg(aux)");
  check(clSetKernelArg(m.aux_kernel, arg++, sizeof skin_count, &skin_count), "clSetKernelArg(aux skin count)");
  // The first-hit records are read only when the frame's aux planes come from the paths (any valid buffer else).
  cl_mem records = m.first_hits ? m.first_hits : m.previous_transforms.mem();
  check(clSetKernelArg(m.aux_kernel, arg++, sizeof(cl_mem), &records), "clSetKernelArg(aux first hits)");
  check(clSetKernelArg(m.aux_kernel, arg, sizeof(cl_mem), &m.aux), "clSetKernelArg(aux output)");
}

void OpenCLTracer::enqueue_aux_rows(const KCamera& camera, size_t first_row, size_t rows, bool straight) {
  Impl& m = *impl_;
  const size_t local[2] = {8, 8};
  const size_t offset[2] = {0, first_row};
  const size_t global[2] = {(camera.width + 7) / 8 * 8, (rows + kGroupRows - 1) / kGroupRows * kGroupRows};
  check(clEnqueueNDRangeKernel(m.queue, m.aux_kernel, 2, offset, global, local, 0, nullptr, m.aux_kernel_done.out()),
        "launching the aux kernel");
  const size_t first = first_row * camera.width, pixels = rows * camera.width;
  if (straight) {
    // Sized for the band's rows above this range too: the packing indexes from the band's first pixel.
    cl_mem packed =
        m.grow(m.packed_aux, m.packed_aux_bytes, (first + pixels) * sizeof(KAuxTexel), "clCreateBuffer(aux texels)");
    m.pack(m.to_texels, m.aux, packed, first, pixels, "packing the aux records", m.aux_packed.out());
  } else {
    // A narrower band keeps the full records (the target converts them row by row): the read waits on
    // the aux kernel itself.
    m.aux_packed.share(m.aux_kernel_done);
  }
}

void OpenCLTracer::read_aux_when_packed(size_t pixels, bool straight) {
  Impl& m = *impl_;
  const size_t bytes = pixels * (straight ? sizeof(KAuxTexel) : sizeof(KAux));
  void* staging = m.aux_staging.reserve(m.context, m.aux_queue, bytes, "allocating page-locked aux memory");
  const cl_event packed = m.aux_packed.get();
  check(clEnqueueReadBuffer(m.aux_queue, straight ? m.packed_aux : m.aux, CL_FALSE, 0, bytes, staging, 1, &packed,
                            m.aux_read.out()),
        "reading the aux band");
  check(clFlush(m.aux_queue), "clFlush(aux)");
}

}  // namespace cohort::tracers
