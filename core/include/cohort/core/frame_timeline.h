// A frame's timeline: every stage a frame goes through, on the track that did it (the core, or one
// tracer), as spans on one process-wide clock. FrameStats carries a frame's spans into stats.json;
// ChromeTraceWriter writes them as a Chrome trace event file that opens in Perfetto
// (ui.perfetto.dev) or chrome://tracing.
#pragma once

#include <chrono>
#include <cstdint>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace cohort::core {

using TimelineClock = std::chrono::steady_clock;

// Milliseconds since the process's timeline epoch (fixed on first use), so that spans from every
// thread and every frame line up.
double timeline_ms(TimelineClock::time_point t);
inline double timeline_now_ms() { return timeline_ms(TimelineClock::now()); }

// Track names: the core's own work, and one track per tracer.
inline constexpr const char* kCoreTrack = "core";
std::string tracer_track(int tracer_id, const std::string& tracer_name);

struct StageSpan {
  std::string track;    // kCoreTrack or tracer_track()
  std::string stage;    // e.g. "apply", "render", "balance", "merge", "world sync", "tone map"
  double start_ms = 0;  // timeline_ms() of its start
  double ms = 0;        // duration
};

void to_json(nlohmann::json& j, const StageSpan& s);

// Stages timed on another clock (a GPU's events), in the order they ran: appended back to back so that the
// last ends at end_ms on the timeline's clock (only where they end is known there), none starting before
// not_before_ms (each clipped to it).
struct ClockedStage {
  const char* stage;
  double ms;
};
void append_spans_ending_at(std::vector<StageSpan>& spans, const std::string& track, double end_ms,
                            const std::vector<ClockedStage>& stages, double not_before_ms = -1e300);

// Times a stage from construction to destruction (or finish()) and appends it to `spans`.
class ScopedStage {
 public:
  ScopedStage(std::vector<StageSpan>& spans, std::string track, std::string stage);
  ~ScopedStage() { finish(); }
  ScopedStage(const ScopedStage&) = delete;
  ScopedStage& operator=(const ScopedStage&) = delete;
  void finish();

 private:
  std::vector<StageSpan>* spans_;
  StageSpan span_;
  TimelineClock::time_point start_;
};

// Streams spans to a Chrome trace event file (JSON array format): one complete ("X") event per span,
// one thread per track, the frame number in each event's args. Written as it goes, so a run that is
// cut short still leaves a file the viewers open.
class ChromeTraceWriter {
 public:
  explicit ChromeTraceWriter(const std::string& path);  // throws std::runtime_error if it cannot be written
  ~ChromeTraceWriter();
  ChromeTraceWriter(const ChromeTraceWriter&) = delete;
  ChromeTraceWriter& operator=(const ChromeTraceWriter&) = delete;

  void add(uint64_t frame, const std::vector<StageSpan>& spans);
  size_t events() const { return events_; }

 private:
  int thread_of(const std::string& track);
  void write(const nlohmann::json& event);

  std::string path_;
  std::ofstream out_;
  std::map<std::string, int> threads_;
  size_t events_ = 0;
};

}  // namespace cohort::core
