// The overlapped frame loop (issue 14; docs/frame-timeline.md): while the tracers render frame N the
// core prepares N+1 (world sync, commits, TLAS), then hands N+1 out and merges, blends, tone-maps and
// writes N while the tracers render N+1. The cost is at most one frame of latency: push() returns the
// frame pushed before it.
//
//   for each frame:  prepare it (submit its commits)  ->  pipeline.push(job)  ->  post-process what came back
//   at the end:      pipeline.drain()                  ->  post-process what came back
// or, preparing the next frame inside push (prepare_next; with two frames in flight the next frame is then
// handed out before the caller's post of the frame returned):
//   next = prepare(0); while (next) { job = next; pipeline.push(job, spans, [&] { return next = prepare(f + 1); }) ... }
#pragma once

#include <functional>
#include <optional>
#include <vector>

#include "cohort/core/frame_buffer.h"
#include "cohort/core/frame_stats.h"
#include "cohort/core/renderer.h"
#include "cohort/core/tracer.h"

namespace cohort::core {

class FramePipeline {
 public:
  struct Delivered {
    BandJob job;        // what the frame was rendered with (its camera, for convergence)
    FrameStats stats;   // its stages include the preparation spans given to push()
  };

  explicit FramePipeline(Renderer& renderer) : renderer_(renderer) {}
  // A frame still in flight is waited for (its tracers' targets belong to the Renderer).
  ~FramePipeline();
  FramePipeline(const FramePipeline&) = delete;
  FramePipeline& operator=(const FramePipeline&) = delete;

  // Hands `job` to the tracers (its commits already submitted) and returns the frame pushed before it,
  // merged into image(); nothing on the first push. `preparation`: the core's spans for this frame so
  // far (e.g. world sync), carried into its stats. When the previous frame cannot be rendered
  // (Renderer::wait_frame throws), `job` is not handed out and the exception propagates; the next push
  // starts afresh. With the Renderer's frames_in_flight 2, `job` is handed out first, before the frame
  // before is waited for (it stays in flight when that one throws): docs/balancing.md, "Two frames in flight".
  std::optional<Delivered> push(const BandJob& job, std::vector<StageSpan> preparation = {});
  // The same, and as soon as `job` is handed out, before the frame before it is merged, `prepare_next`
  // prepares the next frame (submits its commits) and returns its job (or nothing, at the end), which is
  // announced at once (Renderer::announce_frame) instead of by the next push(), after the caller has
  // post-processed the frame returned here. Tracers that take jobs ahead (remote tracers: their nodes)
  // then start on it while this frame renders, without waiting for the core's merge, blend and output of
  // the frame before (docs/cluster.md, "The next frame announced at hand-out"). The returned job is the
  // one to push next (with its frame index; another throws std::logic_error).
  // With the Renderer's frames_in_flight 2 the returned job is also handed out here, as soon as the frame
  // before this one is merged, before that frame is returned for the caller's post: its slot is free then,
  // and a tracer whose band of this frame ends during the caller's post finds its next job queued. The next
  // push of that job then only attaches its `preparation` (docs/balancing.md, "The next frame handed out
  // as soon as a slot frees"). A CUDA tracer's bands kept on its GPU for the post (BandJob::keep_on_device)
  // are then three deep: the caller's post reads the returned frame's while this one and the next render.
  // COHORT_HAND_OUT_AHEAD=0 hands it out at its push instead (the order before, for comparison).
  using PrepareNext = std::function<std::optional<BandJob>()>;
  std::optional<Delivered> push(const BandJob& job, std::vector<StageSpan> preparation, const PrepareNext& prepare_next);
  // Whether the apps announce the next frame at hand-out (push with prepare_next): yes, unless the
  // environment says COHORT_EARLY_ANNOUNCE=0 (the order before, for comparison). `cohort render` and
  // `cohort play` both ask here.
  static bool announces_at_hand_out();
  // Whether push with prepare_next hands the next frame out ahead (two in flight): yes, unless the
  // environment says COHORT_HAND_OUT_AHEAD=0.
  static bool hands_out_ahead();
  // Waits for the frame in flight and returns it merged into image(); nothing when none is. A frame handed
  // out ahead that was never pushed stays in flight: the next drain() returns it.
  std::optional<Delivered> drain();

  // The last delivered frame, as merged; valid until the next push() or drain().
  const FrameBuffer& image() const { return image_; }
  // Its auxiliary planes, when its job asked for them (KFrameParams::aux_outputs); else empty.
  const GBuffer& gbuffer() const { return renderer_.gbuffer(); }
  bool in_flight() const { return in_flight_.has_value(); }

 private:
  struct InFlight {
    BandJob job;
    std::vector<StageSpan> preparation;
  };
  Delivered delivered(InFlight frame, FrameStats stats);
  // push() with the Renderer's frames_in_flight 2: `job` is handed out before the frame before it is
  // waited for (begin, then wait and merge of the one before), so the tracers never wait for the core's
  // turnaround. Where the frame before cannot be rendered, `job` is already handed out and stays in flight.
  std::optional<Delivered> push_two_in_flight(const BandJob& job, std::vector<StageSpan> preparation,
                                              const PrepareNext& prepare_next);
  // Runs prepare_next (when given), announces the job it returns and returns it. If it throws, `restore`
  // runs first, leaving the Renderer as push() promises, and the exception goes on.
  std::optional<BandJob> prepare_and_announce(const PrepareNext& prepare_next, const std::function<void()>& restore);

  Renderer& renderer_;
  FrameBuffer image_;
  std::optional<InFlight> in_flight_;
  // Two in flight: the job prepare_next returned, handed out already (its preparation spans come with its push).
  std::optional<InFlight> ahead_;
};

}  // namespace cohort::core
