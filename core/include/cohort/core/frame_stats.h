// What one frame cost, per tracer and in total; written to JSON by `cohort render` and the benches.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "cohort/core/frame_timeline.h"

namespace cohort::core {

enum class TracerOutcome {
  rendered,   // finished its band in time
  no_rows,    // got an empty band (benched by the balancer, or more tracers than work units): it applied
              // its commits on the side, unwaited, and may have rendered a probe band (probe_rows)
  threw,      // render_band or apply threw: dropped for this frame
  timed_out,  // missed the frame timeout: dropped; it rejoins once it has finished the late work
  busy,       // still finishing late work from an earlier frame: not asked this frame
  away,       // said it cannot take rows now (Tracer::available): given none, not waited for; it gets
              // its commits on the side as a benched tracer does
};
const char* to_string(TracerOutcome outcome);

struct TracerFrameStats {
  int id = 0;
  std::string name;
  TracerOutcome outcome = TracerOutcome::rendered;
  std::string error;           // what it threw, for TracerOutcome::threw
  int row_begin = 0, row_end = 0;
  double ms = 0.0;             // measured cost: commit apply + band render (virtual time: what the tracer reported)
  double idle_ms = 0.0;        // frame_ms - ms for tracers that rendered
  // How long it waited for this frame's job: from the end of its job before to this one's hand-out, when
  // the job came after that one had ended (a "starved" band; with two frames in flight the job should
  // have been queued already); 0 when it was queued in time. Its `wait for job` span shows it on the timeline.
  double job_wait_ms = 0.0;
  int probe_rows = 0;          // no_rows: rows it renders unwaited to be measured (the balancer's probe)
  int recovery_rows = 0;       // rows it re-rendered for dropped tracers
  double recovery_ms = 0.0;
};

struct FrameStats {
  uint64_t frame = 0;
  int rows = 0;
  std::string balancer;
  double frame_ms = 0.0;          // slowest rendering tracer's band time (first round)
  double summed_tracer_ms = 0.0;  // rendering tracers * frame_ms: each of them is occupied for the whole frame
                                  // (a tracer with no rows is not waited for and not counted)
  double idle_ms = 0.0;           // sum of idle_ms
  double idle_percent = 0.0;      // idle_ms / summed_tracer_ms * 100: Brigade's Table 1 metric
  double recovery_ms = 0.0;       // extra time spent re-rendering dropped tracers' rows
  double wall_ms = 0.0;           // wall time of the Renderer's frame (bands, merge, recovery)
  double end_to_end_ms = 0.0;     // the caller's whole frame: world sync to image output (0: not measured);
                                  // with the pipeline this is the latency, and frames overlap
  double interval_ms = 0.0;       // time since the caller delivered the previous frame: 1 / frame rate
  int dropped = 0;                // tracers dropped this frame (threw or timed out)
  double convergence_f = 1.0;     // blend factor used by adaptive convergence (1 = this frame only)
  std::vector<TracerFrameStats> tracers;
  // The frame's timeline: the Renderer's stages (balance, each tracer's apply and render, merge) and
  // what the caller adds around it (world sync, convergence, tone map, output).
  double start_ms = 0.0;          // timeline_ms() when the frame began
  std::vector<StageSpan> stages;
};

void to_json(nlohmann::json& j, const TracerFrameStats& s);
void to_json(nlohmann::json& j, const FrameStats& s);

}  // namespace cohort::core
