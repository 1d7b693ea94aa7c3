// The OpenCL tracer: the shared integrator (kernel/include/cohort/kernel/integrator.h) over the portable two-level BVH
// (kernel/include/cohort/kernel/trace_bvh.h), compiled at run time from kernel text embedded at build time.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "cohort/tracers/device_identity.h"
#include "cohort/tracers/tracer_base.h"

namespace cohort::tracers {

class OpenCLWavefront;

class OpenCLTracer : public TracerBase {
 public:
  struct Options {
    int device = 0;         // index into list_devices(): every device of every platform, in order
    std::string build_options;  // extra OpenCL compiler options
    // With the aux planes from the paths' first hits, the band renders in this many row ranges so that
    // each one's aux finishing, read and host copy overlap the next one's rendering (1: one range, the
    // whole band, then its aux work after it). At most kMaxFirstHitPieces. 2: on two H100s (design card's
    // mix, 1080p) 1 / 2 / 4 pieces took 7.48-7.62 / 7.15-7.32 / 7.34-7.52 ms a frame (docs/balancing.md).
    int first_hit_pieces = 2;
    // Pieces spanning the target's width read their aux texels straight into its rows (pageable memory)
    // instead of into page-locked staging and then copying them on the host: for measuring one against
    // the other on a GPU driver.
    bool aux_into_target = false;
    // Where lit frames that bounce (k_wavefront_renders) render as a wavefront (kernel/wavefront.cl: the
    // rays walked by kernels of their own between shading kernels, the paths in device memory between
    // them; the megakernel's image bit for bit) instead of the megakernel: on GPU devices (the CUDA
    // wavefront's gain), or always, or never. A CPU device keeps the megakernel by default: on PoCL (2-core
    // VM) the wavefront took 60-61 ms a frame against 53-54 (docs/integrator.md). COHORT_OPENCL_WAVEFRONT
    // (the registry): 1 always, 0 never.
    enum class Wavefront { on_gpus, always, never };
    Wavefront wavefront = Wavefront::on_gpus;
    // In the wavefront, next-event estimation's shadow rays left in memory for a walk of their own (where a
    // vertex's rays fit its slots, k_shadow_queue_slots) instead of walked by the shading kernels as they
    // come. COHORT_OPENCL_SHADOW_WALK=0 keeps them in the shading kernels.
    bool shadow_walk = true;
    // On NVIDIA's OpenCL only, -cl-nv-maxrregcount for the wavefront's walk program (the CUDA walks run at
    // 64) and for the main program (the shading kernels and the megakernels); 0: no cap.
    // COHORT_OPENCL_WALK_REGISTERS, COHORT_OPENCL_SHADE_REGISTERS. Shading at 96: large map 1080p on an H100
    // 8.74-8.89 ms uncapped, 8.53-8.61 at 128, 8.34-8.49 at 96 (docs/integrator.md, "The OpenCL wavefront").
    int walk_registers = 64;
    int shade_registers = 96;
    // On a GPU device, the wavefront runs a band of 64 rows or more as two lanes of rows on two queues, so one
    // lane's kernels fill the GPU while the other's drain (CudaTracer::set_wave_lanes' two). Never on a CPU
    // device: nothing to fill there, and the PoCL 5 of Ubuntu 24.04 aborts on the same kernels in two queues
    // (a reference count in its kernel cache). COHORT_OPENCL_WAVE_LANES=0: one lane.
    bool wave_lanes = true;
    // With two frames in flight, the next band's commands (its commit applied first) are enqueued before the
    // tracer waits for the current band, so that the driver's enqueueing (20-30 us a command on NVIDIA)
    // overlaps the band on the device and the next band's kernels follow it without a gap
    // (core::Tracer::enqueues_ahead; docs/balancing.md, "OpenCL enqueues its next band ahead").
    // COHORT_OPENCL_ENQUEUE_AHEAD=0: each band enqueued when its job starts.
    bool enqueue_ahead = true;
    // With enqueue ahead, the band's edges off the compute queue: its row count clear and its parameter and
    // camera writes on an upload queue, its reads (rows, row counts) on a read queue behind its last kernel's
    // event, the buffers they touch in two slots used in turn; so the next band's kernels follow this band's
    // on the device with no transfer between them (docs/balancing.md, "OpenCL's bands back to back on the
    // device"). On GPU devices (their copy engines run beside the kernels), or always, or never. A CPU device
    // keeps one queue by default: on PoCL (2-core VM) a band's read sometimes ran only after the next band's
    // kernels, a whole band late (p95 frame 100-115 ms against 54-61, OpenCL alone at 320x180).
    // COHORT_OPENCL_TRANSFER_QUEUE (the registry): 1 always, 0 never.
    enum class TransferQueue { on_gpus, always, never };
    TransferQueue transfer_queue = TransferQueue::on_gpus;
    // With the transfer queues, a band's colour and row counts are read by DMA into page-locked staging (one
    // per slot) and copied into the target's rows on the host once read, instead of read straight into the target's
    // pageable rows, which NVIDIA's OpenCL copies through staging of its own at a few GB/s (0.6 ms from the
    // last kernel to the read's end for a 360-row 720p band in the design card's mix on nvidia-h100-x2).
    // COHORT_OPENCL_PINNED_READS=0: straight into the target.
    bool pinned_band_reads = true;
    // With the transfer queues, once bands go ahead (two frames in flight): a band that could not go ahead (its
    // job came after the band before had ended) costs the balancer its wall time less its enqueueing, which a
    // job that came in time would have hidden. Without it a tracer that ends its bands before the frame's
    // slowest one gets its jobs too late to enqueue them ahead, pays the enqueueing every band, looks slow to
    // the balancer, keeps few rows and so keeps ending early (nvidia-h100-x2, cuda:0 + opencl:2: some runs
    // settled at 448 / 272 rows and 1.57 ms a frame, others at 336 / 384 and 1.31). COHORT_OPENCL_LATE_JOB_COST.
    bool late_job_cost = true;
  };
  static constexpr int kMaxFirstHitPieces = 8;
  // The pieces' first rows, relative to the band, and `rows` last: up to `pieces` ranges of whole work
  // groups (multiples of `group_rows`, the last one the remainder), none empty. Every kernel of a piece
  // runs over whole work groups from its first row, so a piece that ended inside a group would render
  // the next piece's first rows too.
  static std::vector<size_t> piece_starts(size_t rows, int pieces, size_t group_rows);
  // Throws std::runtime_error when there is no such device or the kernel does not compile (the
  // message carries the build log), std::invalid_argument for a piece count outside 1-kMaxFirstHitPieces.
  explicit OpenCLTracer(const Options& options);
  ~OpenCLTracer() override;
  OpenCLTracer(const OpenCLTracer&) = delete;
  OpenCLTracer& operator=(const OpenCLTracer&) = delete;

  std::string name() const override;
  bool renders_on_gpu() const override;
  // Whether this tracer renders lit frames that bounce as a wavefront (Options::wavefront on its device),
  // and whether the wavefront's shadow rays have their own walk (Options::shadow_walk).
  bool wavefront() const;
  bool shadow_walk() const;
  using core::Tracer::render_band;
  core::BandResult render_band(const core::BandJob& job, core::BandBuffer& target) override;
  bool enqueues_ahead() const override;
  void drop_enqueued_ahead() override;
  // Bands enqueued ahead while the band before rendered, those of them that render_band then found
  // enqueued (and only waited for), and those drained unrendered (drop_enqueued_ahead, or a job that did not
  // match); for tests and logs.
  size_t bands_enqueued_ahead() const;
  size_t bands_finished_ahead() const;
  size_t bands_dropped_ahead() const;
  // Bands enqueued ahead with their edges off the compute queue (Options::transfer_queue): their kernels
  // queued straight behind the band before's, whose reads went on the read queue.
  size_t bands_back_to_back() const;
  // Whether the band's edges go on the upload and read queues (Options::transfer_queue on this device, with
  // enqueue_ahead).
  bool transfer_queues() const;
  // Bands whose colour came through page-locked staging (Options::pinned_band_reads).
  size_t bands_read_through_staging() const;

  // "platform / device" for every OpenCL device on this machine, in the order Options::device counts.
  static std::vector<std::string> list_devices();
  struct DeviceDescription {
    std::string label;   // as list_devices() gives it
    DeviceKind kind = DeviceKind::other;
    // From cl_khr_pci_bus_info or NVIDIA's cl_nv_device_attribute_query where the device lists one;
    // unknown otherwise (PoCL's CPU device).
    PciBusId pci;
  };
  // The same devices in the same order, with their kind and PCI address.
  static std::vector<DeviceDescription> describe_devices();

 private:
  void upload(const commit::ChangeSet& changes) override;
  bool skins_on_device() const override { return true; }
  // The band's auxiliary planes from centre rays (kernel/aux_outputs.h), in three steps around the band's
  // kernel: the aux kernel (and the packing to texels when the band spans the target's width,
  // `straight`) enqueued before it; the read into page-locked memory on the second queue, overlapping it;
  // the copy into the target once that read is done (render_band, before the next band is enqueued).
  void enqueue_aux(const core::BandJob& job, const KCamera& camera, size_t rows, bool straight);
  void read_aux_when_packed(size_t pixels, bool straight);
  // The aux kernel's arguments for this band (and the previous camera, transforms and joints it reads),
  // then its launch (and packing) over the band's rows [first_row, first_row + rows).
  void prepare_aux(const core::BandJob& job, const KCamera& camera, size_t rows);
  void enqueue_aux_rows(const KCamera& camera, size_t first_row, size_t rows, bool straight);
  // The band with its aux planes from the paths' first hits, in pieces (Options::first_hit_pieces):
  // per piece, on the main queue, the band's kernel, the aux kernel, the packings; on the second queue
  // the piece's aux and colour reads behind them; on the host its aux copy, while later pieces render.
  // wave: the wavefront that renders each piece's rows, or null for the megakernel.
  core::BandResult render_first_hits_in_pieces(const core::BandJob& job, core::BandBuffer& target,
                                               const KFrameParams& params, const KCamera& camera, bool straight,
                                               OpenCLWavefront* wave);

  // A band whose commands are all enqueued (render_band's, or the next one's ahead), and its end: the wait
  // for its last command, its rows stored where they came down elsewhere, its clock.
  struct EnqueuedBand;
  // ahead: enqueued while the band before is still in the queues (its uploads then go on the upload queue).
  std::unique_ptr<EnqueuedBand> enqueue_band(const core::BandJob& job, core::BandBuffer& target, bool ahead);
  core::BandResult finish_band(EnqueuedBand& band);
  // Inside render_band, the current band enqueued: the next band enqueued too when the worker has it
  // queued before the current band is done (Tracer::queued_next) and it can go ahead.
  void enqueue_next_ahead(const EnqueuedBand& current);

  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cohort::tracers
