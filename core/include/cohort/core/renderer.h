// The frame loop (Brigade, §4.2): one worker thread per tracer. Per frame the core asks the balancer
// for row bands, hands every tracer its job, and waits; there is no communication with a tracer while
// it renders. Each tracer renders into its own full-size buffer and the core merges the bands.
//
// Commits travel one way: every tracer has its own commit::CommitChannel (docs/commit-buffers.md), a
// pair of buffers with a byte budget. submit_commit() folds a frame's records into every tracer's
// pending buffer while they render; when a job is handed out, the pending buffer becomes the one the
// tracer applies before rendering (a tracer that missed frames gets them coalesced into one commit).
// A pending buffer over budget becomes a full resync to the caller's snapshot, and so does the next
// commit of a tracer whose apply() threw: such a tracer renders nothing until it has its resync.
//
// A tracer the balancer gives no rows (benched) still gets its commits: it applies them on the side,
// with the probe band the balancer may ask for, and the frame does not wait for it; what it measured
// reaches the balancer at the next frame that finds it done.
//
// Faults: a tracer that throws, or has not finished when the frame timeout expires, is dropped for the
// frame; its rows are split among the tracers that finished (and benched ones that are idle) and re-rendered, and the frame is still
// delivered. A timed-out tracer keeps running on its own thread; it takes part again from the first
// frame that starts after it has finished. One that never returns does not block shutdown.
//
// Two frames in flight (RendererOptions::frames_in_flight = 2): frame N+1 may be begun before N is
// waited for, so each worker holds up to two jobs and starts N+1 the moment its band of N is done,
// instead of idling through the core's turnaround and the slowest band (docs/balancing.md, "Two frames
// in flight").
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "cohort/balance/balancer.h"
#include "cohort/commit/commit_buffer.h"
#include "cohort/commit/commit_channel.h"
#include "cohort/core/band_buffer.h"
#include "cohort/core/frame_buffer.h"
#include "cohort/core/frame_stats.h"
#include "cohort/core/gbuffer.h"
#include "cohort/core/tracer.h"

namespace cohort::core {

struct RendererOptions {
  std::string balancer = "perfect-smooth";
  balance::BalancerOptions balancer_options;
  std::chrono::milliseconds frame_timeout{2000};
  // How long the destructor waits for tracers still inside a job before leaving them behind.
  std::chrono::milliseconds shutdown_timeout{2000};
  // Balance on the times tracers report (BandResult::device_ms) instead of wall-clock time. Simulated
  // tracers on a virtual clock need this; real GPU tracers may prefer their kernel times.
  bool use_reported_time = false;
  // Pass the tracers' per-row work counts (BandResult::row_work) to the balancer as its cost proxy.
  bool use_row_work = true;
  // Per tracer: past this many bytes of pending records, it gets a full resync instead.
  size_t commit_budget_bytes = 32u << 20;
  // What the tracers render their bands into (core/band_buffer.h); the merge converts to the float
  // frame. The apps take RGB9E5 (4 bytes a pixel); RGBA32F keeps values exact.
  BandFormat band_format = BandFormat::rgba32f;
  // A benched tracer with no probe to render gets its commits every this many frames (they coalesce in
  // its channel meanwhile), not every frame: applying them is pure overhead while it sits out, and a CPU
  // tracer's apply (skinning, refits, its TLAS on every core) slows the host's part of the frame. 1: every
  // frame. Whatever it skipped is applied before it renders again.
  int benched_commit_every = 1;
  // How long a thread polls before it blocks where the other side is about to answer (cohort/core/brief_spin.h):
  // a worker after its band, for its next job; the core from shortly before the frame's bands are due
  // (the slowest one's last time) to this long after. 0: block at once.
  std::chrono::microseconds handoff_spin{150};
  // 1: a frame is begun only once the one before it has been waited for. 2: begin_frame() may hand out
  // frame N+1 while N is still in flight (each worker then queues N+1's job behind N's); the balancer
  // divides N+1 by the costs measured for N-1. Anything else throws std::invalid_argument.
  int frames_in_flight = 1;
};

class Renderer {
 public:
  // Takes ownership of the tracers; tracer i gets id i. Throws std::invalid_argument if there are none
  // or the balancer name is unknown.
  Renderer(std::vector<std::unique_ptr<Tracer>> tracers, RendererOptions options);
  // Waits for every tracer to return from its current job, at most shutdown_timeout; a tracer that has
  // not returned by then is logged and left behind on its own thread, which keeps it (and what it
  // renders into) alive until it returns, if ever.
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Fold a frame's records into every tracer's pending commit, for their next job. `snapshot` returns
  // the scene with these records applied (WorldSync::snapshot); it is called only when a tracer needs
  // a full resync, and may be left out for full commits. Submitting incremental records without one
  // and then needing a resync throws std::logic_error. The first commit seeds the channels: a full
  // one, or an incremental one over an empty scene. Call from the core's thread.
  void submit_commit(const commit::CommitBuffer& records, commit::CommitChannel::Snapshot snapshot = {});
  // Per tracer: the channel's counts (bytes, coalesced frames, overflows, resyncs).
  commit::CommitStats commit_stats(int tracer) const;

  // Render one frame of job.camera.width x job.camera.height into `out` (resized if needed).
  // job.params.row_begin/row_end are set per band. row_cost_proxy (optional, one value per row) is
  // passed to the balancer; without one, the per-row work the tracers reported last frame
  // (BandResult::row_work) is passed when it covers every row. Throws std::runtime_error when no tracer could render some rows.
  FrameStats render(const BandJob& job, FrameBuffer& out, const std::vector<float>& row_cost_proxy = {});
  // render() in pieces, for a pipeline with at most one frame of latency (docs/frame-timeline.md):
  // begin_frame() hands out the bands and returns at once; wait_frame() waits for them, re-renders
  // dropped tracers' rows and returns the stats; merge_frame() copies the bands into `out` (resized if
  // needed). Between wait_frame() and merge_frame() the next frame may be begun: every tracer renders
  // into one of two targets by frame parity, so frame N is merged while N+1 renders. finish_frame()
  // is wait_frame() then merge_frame(). Commits submitted after begin_frame() go to the next frame.
  // With frames_in_flight 2, begin_frame() may also come before wait_frame() of the frame before (but
  // never a third frame, nor one whose target parity is still unmerged): wait_frame() waits for the
  // oldest frame begun. render() needs no frame in flight.
  // `out` must stay alive until merge_frame() returns; only merge_frame() writes it. Calls out of order
  // throw std::logic_error.
  void begin_frame(const BandJob& job, FrameBuffer& out, const std::vector<float>& row_cost_proxy = {});
  // The job the next begin_frame() will hand out, known before the frame in flight is waited for (its
  // commits submitted): tracers that take jobs ahead (Tracer::takes_jobs_ahead) may start on it while
  // their band of the frame in flight ends. begin_frame() withdraws it. FramePipeline::push calls it.
  void announce_frame(const BandJob& job);
  // Whether any tracer takes jobs ahead (remote tracers): only then does an early announcement help.
  bool takes_jobs_ahead() const { return any_takes_jobs_ahead_; }
  int frames_in_flight() const { return options_.frames_in_flight; }
  // Frames begun and not yet waited for.
  int frames_begun() const { return static_cast<int>(pending_.size()); }
  FrameStats wait_frame();
  void merge_frame(FrameStats& stats);
  FrameStats finish_frame();
  // The auxiliary planes of the last merged frame, when its job set params.aux_outputs (else empty).
  const GBuffer& gbuffer() const { return gbuffer_; }
  // Packed merging: the frame's bands are copied as the tracers wrote them (band format, aux texels) into
  // packed_frame() instead of being converted into the float frame and gbuffer(), which then stay as they
  // were. For a consumer that unpacks elsewhere (CudaFramePost: half the bytes cross the bus, and the
  // host's conversions are skipped). Call between frames.
  void set_packed_merge(bool on) { packed_merge_ = on; }
  bool packed_merge() const { return packed_merge_; }
  const BandBuffer& packed_frame() const { return packed_; }
  // With a packed merge whose consumer runs on CUDA device `device` (-1: off): each frame's bands are
  // offered to stay on their GPUs (BandJob::keep_on_device); those a tracer kept are listed in
  // packed_device_rows() instead of being copied (their rows in packed_frame() are stale). Re-rendered
  // rows and probes always come through the host. Call between frames.
  void set_device_bands(int device) { device_bands_for_ = device; }
  const std::vector<DeviceBandRows>& packed_device_rows() const { return packed_device_rows_; }

  int tracer_count() const;
  std::string tracer_name(int tracer) const;
  const std::string& balancer_name() const { return options_.balancer; }
  // Switch balancers between frames (the viewer's B key); the new one starts without history.
  // Throws std::invalid_argument for an unknown name and keeps the current one.
  void set_balancer(const std::string& name);
  // Forget balancing history (e.g. on a camera cut).
  void reset_balancer();

 private:
  struct Worker;
  // What a worker reports of one job (kept per job: with two jobs queued, the second may end before the
  // core has collected the first).
  struct Outcome {
    uint64_t job_id = 0;
    bool ok = false;
    std::string error;
    double wall_ms = 0.0;
    double reported_ms = 0.0;
    double balance_ms = 0.0;  // BandResult::balance_ms
    double apply_ms = 0.0;
    double waited_ms = -1.0;  // from the end of the worker's job before to this one's start (< 0: no job before)
    // From the end of the worker's job before to this job's hand-out, when it was handed out after that
    // job had ended (the worker was starved of work); 0 when it was queued in time or is the first.
    double job_wait_ms = 0.0;
    std::vector<float> row_work;
    DeviceBand device_band;        // the band, when it stayed on a GPU
    std::vector<StageSpan> spans;  // the job's apply and render stages
  };
  struct Assignment {
    int worker;
    balance::Band band;
    bool probe = false;  // rendered to be measured only: nobody waits for it, its rows are not merged
    DeviceBand device;   // where its rows are when the tracer kept them on a GPU (set once delivered)
    std::chrono::steady_clock::time_point due{};  // when its band should end (set by assign)
    bool away = false;   // an away tracer's commits on the side (Tracer::while_away)
  };
  struct RoundResult {
    std::vector<int> finished;   // workers that rendered their band
    std::vector<Assignment> delivered;  // their bands, to merge
    std::vector<int> threw;
    std::vector<int> timed_out;
    std::vector<std::pair<int, Outcome>> outcomes;  // of the workers that finished or threw
    const Outcome& of(int worker) const;
  };

  struct PendingFrame {
    BandJob job;
    FrameBuffer* out = nullptr;
    FrameStats stats;
    std::vector<Assignment> assignments;
    std::vector<uint64_t> ids;
    std::chrono::steady_clock::time_point start;
    int slot = 0;                        // the workers' target this frame renders into
    std::vector<uint64_t> handed_out;    // every job of it, side jobs included
    double since_previous_ms = 0.0;      // from the previous frame's start to this one's
    std::vector<Assignment> delivered;   // bands (and re-rendered rows) waiting to be merged
  };

  // Hands each assignment to its worker (with the queued commits when with_commits), to render into
  // its target `slot`, and returns the job ids; collect() waits for them until the deadline.
  std::vector<uint64_t> assign(std::vector<Assignment>& assignments, const BandJob& job, int slot,
                               bool with_commits);
  RoundResult collect(const std::vector<Assignment>& assignments, const std::vector<uint64_t>& ids,
                      std::chrono::steady_clock::time_point deadline, std::vector<StageSpan>& stages);
  // Copies delivered bands from the workers' targets `slot` into out.
  void merge(const std::vector<Assignment>& bands, int slot, FrameBuffer& out) const;
  // Calls copy(band buffer, row_begin, row_end) over every band's rows of that slot, in ranges on the
  // host's threads: the one loop of every merge (floats, aux planes, packed).
  void for_band_rows(const std::vector<Assignment>& bands, int slot,
                     const std::function<void(const BandBuffer&, int, int)>& copy) const;
  double measured_ms(const Outcome& o) const;
  // A benched tracer's unwaited job (commits, maybe a probe) that has ended: its measurement joins
  // last_measurements_ and its stages the frame's. Call with the completion mutex held.
  void harvest_side_job(Worker& w, std::vector<StageSpan>& stages);
  std::shared_ptr<const commit::TracerScene> resync_scene();

  RendererOptions options_;
  std::unique_ptr<balance::Balancer> balancer_;
  std::vector<std::shared_ptr<Worker>> workers_;
  std::vector<balance::TracerMeasurement> last_measurements_;
  std::vector<float> row_work_;            // this frame's per-row work counts, as tracers report them
  std::vector<uint8_t> row_work_known_;
  uint64_t next_job_ = 1;
  commit::CommitChannel::Snapshot snapshot_;                 // the latest submitted records' scene
  std::shared_ptr<const commit::TracerScene> full_scene_;    // the latest full commit's scene
  bool records_since_full_ = false;
  uint64_t commit_frame_ = 0;                                // frame of the latest submitted commit
  // The announced next job (announce_frame), shared with the tracers' hooks.
  struct Announcement {
    std::mutex mutex;
    std::optional<BandJob> job;
  };
  std::shared_ptr<Announcement> announcement_ = std::make_shared<Announcement>();
  bool any_takes_jobs_ahead_ = false;
  std::deque<std::unique_ptr<PendingFrame>> pending_;  // begun, not yet waited for, oldest first
  std::unique_ptr<PendingFrame> unmerged_;   // waited for, bands not yet merged
  int next_slot_ = 0;
  std::optional<std::chrono::steady_clock::time_point> last_frame_start_;  // for the balancer's frame interval
  // When the last wait_frame's bands were back: with two frames in flight, the next frame's timeout
  // counts from there (its bands start only after the frame before's).
  std::chrono::steady_clock::time_point last_round_end_{};
  GBuffer gbuffer_;
  bool packed_merge_ = false;
  BandBuffer packed_;
  int device_bands_for_ = -1;
  std::vector<DeviceBandRows> packed_device_rows_;
};

}  // namespace cohort::core
