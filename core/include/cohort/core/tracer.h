// The interface every tracer implements. A tracer runs on its own worker thread; once a frame has
// started the core does not talk to it until it reports its band done (Brigade, §4.2).
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "cohort/commit/commit_buffer.h"
#include "cohort/core/band_buffer.h"
#include "cohort/core/frame_buffer.h"
#include "cohort/kernel/layout.h"

namespace cohort::core {

struct BandJob {
  KFrameParams params{};   // row_begin/row_end name the band, in full-resolution rows
  KCamera camera{};
  // The previous frame's camera, for motion vectors when params.aux_outputs is set; a width of 0 means
  // none (the frame is its own previous: camera motion 0).
  KCamera previous_camera{};
  // The CUDA device the core will take this band from (the GPU post-processing's, set by the Renderer
  // for a packed merge): a tracer that can hand its rows over there leaves them on its GPU and reports
  // them in BandResult::device instead of writing the target (the rows never cross the bus twice);
  // -1: write the target, as always. Remote tracers clear it before the job travels. A kept band must
  // stay until the tracer has kept two more: with two frames in flight the post reads frame N's while
  // N+1 and N+2 render (core/frame_pipeline.h).
  int keep_on_device = -1;
};

struct BandResult {
  double device_ms = 0.0;  // time the tracer measured itself (kernel time for GPUs); 0 if it cannot
  // A GPU's own clock for the band's way back after its kernels (format conversion and download, or the
  // copy it keeps for the post); 0 if it cannot tell. With device_ms, the timeline shows them inside the
  // render span (the rest of it is the host's: launches, waits, wake-ups).
  double transfer_ms = 0.0;
  // Optional: a work count per row of the band, row_begin first (e.g. rays traced in that row). The
  // core hands it to the balancer as an image-space cost map for the next frame. Empty if not counted.
  std::vector<float> row_work;
  // Set when the tracer kept its band on a GPU (BandJob::keep_on_device): the target's rows are stale.
  DeviceBand device;
  // When > 0: what the band costs the tracer, for the balancer, in place of the wall time of its job (a
  // tracer that began the band ahead of its job, Tracer::takes_jobs_ahead: its wall time leaves out the
  // head start, and the balancer divides rows by speed).
  double balance_ms = 0.0;
};

class Tracer {
 public:
  virtual ~Tracer() = default;
  virtual std::string name() const = 0;
  // Whether the tracer's rays run on a GPU (its frames then come back faster than the host can
  // post-process them; see apps' choice of convergence).
  virtual bool renders_on_gpu() const { return false; }
  // Bring the tracer's scene copy (and device buffers) up to date. Called on the tracer's thread.
  virtual void apply(const commit::CommitBuffer& commit) = 0;
  // Render rows [row_begin, row_end) of the frame into target (full frame size, in the format it
  // has; only those rows are written).
  virtual BandResult render_band(const BandJob& job, BandBuffer& target) = 0;
  // The band as consecutive pieces of rows, [cuts[i], cuts[i + 1]) with cuts[0] = row_begin and
  // cuts.back() = row_end, calling `ready(i)` on this thread once piece i's rows (and aux texels) are in
  // the target, in order, while the pieces after it still render: a remote node (tracers/mpi) sends each
  // piece as soon as it is ready. The rows always go to the target (keep_on_device is ignored); the
  // result's device_ms sums the pieces'. By default one render_band per piece; a GPU tracer overrides
  // it to queue every piece at once and download each while the next renders.
  virtual BandResult render_band_in_pieces(const BandJob& job, BandBuffer& target, const std::vector<int>& cuts,
                                           const std::function<void(size_t)>& ready);
  // The same into a float frame (tests, benches): rendered as RGBA32F and copied into those rows of
  // target, which is resized to the camera's size when it differs. Derived classes say
  // `using core::Tracer::render_band;` so that it is not hidden.
  BandResult render_band(const BandJob& job, FrameBuffer& target);

  // Commits ahead. A tracer whose apply() only hands the commit on and whose scene copy changes only
  // after the band it is rendering (a remote tracer: its node applies what comes after the band's job
  // once that band is rendered) may take the commits the core submits while it renders, instead of with
  // its next job, so that they travel, and are applied, while the band renders (docs/cluster.md). Such a
  // tracer says so here and calls apply_commits_ahead() from inside render_band(), after whatever the
  // job must see has left; the Renderer then applies, through apply() on this thread, what it has
  // published for this tracer since the job was handed out. Everything else stays as it is: the next
  // job still brings what was published after that.
  virtual bool takes_commits_ahead() const { return false; }
  using CommitsAhead = std::function<void()>;
  // The Renderer's hook (set once, before the first job); without one apply_commits_ahead does nothing.
  void set_commits_ahead(CommitsAhead hook) { commits_ahead_ = std::move(hook); }

  // Jobs ahead. The core knows the next frame's job (camera, parameters) before it waits for the frame
  // in flight (FramePipeline::push announces it, its commits already submitted), but divides its rows
  // only once every band is back. A tracer that can start on that frame before its job comes (a remote
  // tracer: its node would otherwise idle while its band travels back and the core turns the frame
  // around) says so here and may call next_job_announced() from inside render_band(): the announced
  // job, with no rows, or nothing. Whatever it renders ahead is its own business and must not touch the
  // target; the job it is handed next is what counts (its rows, and its commit, which may change the
  // scene after the announcement).
  virtual bool takes_jobs_ahead() const { return false; }
  using NextJob = std::function<std::optional<BandJob>()>;
  void set_next_job(NextJob hook) { next_job_ = std::move(hook); }

  // Enqueue ahead. With two frames in flight a worker holds its next job (rows final, target known) while
  // the current band renders. A tracer whose device runs its commands in order behind the host's enqueueing
  // (an OpenCL queue, whose driver costs tens of microseconds a command) says so here and may call
  // queued_next(band_done) from inside render_band(), once the current band's commands are all enqueued,
  // instead of waiting for them: with two frames in flight it waits until the next job is queued (the core
  // hands it out once it has turned the frame before around) or band_done() is true, with one it only looks.
  // It gives the next job and its target, that job's commit applied first on this thread (through apply(),
  // exactly once: the job no longer brings it), or nothing (the band ended first, no job queued, a recovery
  // or probe job, a full resync due, a diverged scene). band_done is called on this thread (not under the
  // worker's lock); the tracer calls wake_queued_next() from any thread (a device's completion callback) once
  // it may have turned true (without that it is asked again every millisecond). The tracer then
  // enqueues that band's commands into that target and waits for the current band only; the next
  // render_band() with the same job and target finds them enqueued and only waits and finishes. What the core publishes after the next job's hand-out still goes
  // with the job after. When a job that was enqueued ahead will not be rendered (the Renderer shuts down
  // first), the worker calls drop_enqueued_ahead() on this thread: the tracer waits for those commands, so
  // that nothing writes into the target after.
  virtual bool enqueues_ahead() const { return false; }
  struct QueuedNext {
    BandJob job;
    BandBuffer* target = nullptr;
  };
  using BandDone = std::function<bool()>;
  using QueuedNextHook = std::function<std::optional<QueuedNext>(const BandDone&)>;
  // The Renderer's hooks (set once, before the first job).
  void set_queued_next(QueuedNextHook hook, std::function<void()> wake) {
    queued_next_ = std::move(hook);
    wake_queued_next_ = std::move(wake);
  }
  // Wakes a queued_next() waiting on band_done (thread-safe; nothing when none waits).
  void wake_queued_next() const {
    if (wake_queued_next_) wake_queued_next_();
  }
  virtual void drop_enqueued_ahead() {}

  // A tracer whose scene is gone (a remote tracer whose slot a new node took: it starts with nothing)
  // asks for a full resync here; the Renderer sends one with its next job. Read on the core thread
  // between the tracer's jobs.
  virtual bool wants_full_resync() const { return false; }

  // Whether the tracer can take rows now. One that cannot (a remote tracer whose node has not answered
  // its last band and whose slot no new node has taken) is given none: the frame is divided among the
  // others, it is not waited for, and it keeps getting its commits as a benched tracer does (FrameStats:
  // outcome "away"). Without this its band would fail at once every frame and its rows be re-rendered
  // after the others' bands: one late frame per frame instead of one in all. Read on the core thread
  // while the tracer's own thread may be inside apply() or render_band(): it must be thread-safe.
  virtual bool available() const { return true; }
  // Called on the tracer's thread with each job the Renderer hands it while it is away (its commits on the
  // side, which may be empty): a tracer that waits for something to come back (a remote node's late answer)
  // looks for it here, so that available() turns true again.
  virtual void while_away() {}
  // Whether, while away, the tracer wants its side job (and so while_away()) every frame rather than every
  // RendererOptions::benched_commit_every frames: one that waits for an answer that brings it back soon (a
  // remote node that joined, warming up after its full resync, says when it is ready) would otherwise take
  // rows up to that many frames late. Read on the core thread, like available(): it must be thread-safe.
  virtual bool checks_in_every_frame() const { return false; }

 protected:
  void apply_commits_ahead() {
    if (commits_ahead_) commits_ahead_();
  }
  std::optional<BandJob> next_job_announced() const { return next_job_ ? next_job_() : std::nullopt; }
  std::optional<QueuedNext> queued_next(const BandDone& band_done) const {
    return queued_next_ ? queued_next_(band_done) : std::nullopt;
  }

 private:
  CommitsAhead commits_ahead_;
  NextJob next_job_;
  QueuedNextHook queued_next_;
  std::function<void()> wake_queued_next_;
};

}  // namespace cohort::core
