// The CUDA tracer: one per GPU. Device buffers mirror the tracer's commit::TracerScene; commits are
// applied with async copies (the arrays a frame's commit changes, per band slot, on the band's stream); the
// band is rendered by the shared integrator (kernel/include/cohort/kernel/) compiled as CUDA, and kernel
// time is measured with CUDA events.
#pragma once

#include <memory>
#include <string>

#include "cohort/tracers/device_identity.h"
#include "cohort/tracers/tracer_base.h"

namespace cohort::tracers {

// Number of usable CUDA devices; 0 when there is no driver or no GPU (never throws).
int cuda_device_count();
std::string cuda_device_name(int device);
// The device's PCI address (unknown when the driver cannot say): how the registry sees that an OpenCL
// device is the same GPU.
PciBusId cuda_device_pci_bus_id(int device);

class CudaTracer final : public TracerBase {
 public:
  explicit CudaTracer(int device);
  ~CudaTracer() override;
  std::string name() const override;
  bool renders_on_gpu() const override { return true; }
  using core::Tracer::render_band;
  core::BandResult render_band(const core::BandJob& job, core::BandBuffer& target) override;
  // Every piece's kernel queued at once, each piece downloaded on the copy engine while the next renders
  // (a remote node's band, tracers/mpi); frames with aux outputs take the default, piece by piece.
  core::BandResult render_band_in_pieces(const core::BandJob& job, core::BandBuffer& target, const std::vector<int>& cuts,
                                         const std::function<void(size_t)>& ready) override;

  // Ray counting for benchmarks (off by default: it costs a reduction per warp).
  struct RayCounts {
    unsigned long long closest = 0, occlusion = 0;
  };
  void set_ray_counting(bool on);
  // Bounce rays walked by a kernel of their own between shading kernels (the wavefront) instead of the
  // megakernel; same image, faster (docs/integrator.md). On unless COHORT_CUDA_WAVEFRONT=0.
  void set_wavefront(bool on);
  bool wavefront() const;
  // In the wavefront, next-event estimation's shadow rays walked by a kernel of their own instead of by the
  // shading kernels; same image (docs/integrator.md). On unless COHORT_CUDA_SHADOW_WALK=0.
  void set_shadow_walk(bool on);
  // The wavefront runs a band as up to `lanes` lanes of rows (1 to 4), each on a stream of its own, so one
  // lane's kernels fill the GPU while another's drain (default: COHORT_CUDA_WAVE_LANES, else 2). The image
  // is the same for any count.
  void set_wave_lanes(int lanes);
  // Each band runs on one of two streams in turn, and the next band's kernels may start once the current
  // band's lanes have come to their last `kernels` kernels (0: once its kernels are done), so that the next
  // band fills the SMs while this one's last waves drain. Only bands enqueued ahead (two frames in flight) can
  // overlap, and only after commits that change no shared array (geometry, textures, skins). The image is the
  // same for any value (docs/balancing.md, "Bands that overlap"). Default: COHORT_CUDA_BAND_OVERLAP, else 2.
  void set_band_overlap(int kernels);
  int band_overlap() const;
  // Bands whose kernels were let start at the band before's release point (not after its whole kernels).
  size_t bands_overlapping() const;
  // With two frames in flight, the next band's commands (its commit applied first) are enqueued while the
  // current band renders (core::Tracer::enqueues_ahead), so that its kernels follow on the GPU without the
  // host's turn-around between bands (docs/balancing.md). On unless COHORT_CUDA_ENQUEUE_AHEAD=0.
  void set_enqueue_ahead(bool on);
  bool enqueues_ahead() const override;
  void drop_enqueued_ahead() override;
  // Bands enqueued ahead, those their job then found enqueued, and those dropped (their job never came).
  size_t bands_enqueued_ahead() const;
  size_t bands_finished_ahead() const;
  size_t bands_dropped_ahead() const;
  bool shadow_walk() const;
  RayCounts last_ray_counts() const;
  int device() const;

 private:
  void upload(const commit::ChangeSet& changes) override;
  bool skins_on_device() const override { return true; }

  struct BandSlot;
  struct EnqueuedBand;
  // The band's commands on the stream (render_band's first half); a band of no rows enqueues nothing.
  EnqueuedBand enqueue_band(const core::BandJob& job, core::BandBuffer& target);
  // With enqueue ahead: waits for the next job until `current` is back, and enqueues it.
  void enqueue_next_ahead(const EnqueuedBand& current);

  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cohort::tracers
