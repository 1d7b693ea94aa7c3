#include "cohort/core/frame_stats.h"

#include <nlohmann/json.hpp>

namespace cohort::core {

const char* to_string(TracerOutcome outcome) {
  switch (outcome) {
    case TracerOutcome::rendered: return "rendered";
    case TracerOutcome::no_rows: return "no_rows";
    case TracerOutcome::threw: return "threw";
    case TracerOutcome::timed_out: return "timed_out";
    case TracerOutcome::busy: return "busy";
    case TracerOutcome::away: return "away";
  }
  return "unknown";
}

void to_json(nlohmann::json& j, const TracerFrameStats& s) {
  j = nlohmann::json{{"id", s.id},           {"name", s.name},     {"outcome", to_string(s.outcome)},
                     {"row_begin", s.row_begin}, {"row_end", s.row_end}, {"rows", s.row_end - s.row_begin},
                     {"ms", s.ms},           {"idle_ms", s.idle_ms}, {"job_wait_ms", s.job_wait_ms},
                     {"recovery_rows", s.recovery_rows},
                     {"recovery_ms", s.recovery_ms}};
  if (s.probe_rows > 0) j["probe_rows"] = s.probe_rows;
  if (!s.error.empty()) j["error"] = s.error;
}

void to_json(nlohmann::json& j, const FrameStats& s) {
  j = nlohmann::json{{"frame", s.frame},
                     {"rows", s.rows},
                     {"balancer", s.balancer},
                     {"frame_ms", s.frame_ms},
                     {"summed_tracer_ms", s.summed_tracer_ms},
                     {"idle_ms", s.idle_ms},
                     {"idle_percent", s.idle_percent},
                     {"recovery_ms", s.recovery_ms},
                     {"wall_ms", s.wall_ms},
                     {"end_to_end_ms", s.end_to_end_ms},
                     {"interval_ms", s.interval_ms},
                     {"dropped", s.dropped},
                     {"convergence_f", s.convergence_f},
                     {"tracers", s.tracers},
                     {"start_ms", s.start_ms},
                     {"stages", s.stages}};
}

}  // namespace cohort::core
