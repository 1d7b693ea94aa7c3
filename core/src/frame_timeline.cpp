#include "cohort/core/frame_timeline.h"

#include <algorithm>

#include <stdexcept>

#include <nlohmann/json.hpp>

namespace cohort::core {

double timeline_ms(TimelineClock::time_point t) {
  static const TimelineClock::time_point epoch = TimelineClock::now();
  return std::chrono::duration<double, std::milli>(t - epoch).count();
}

std::string tracer_track(int tracer_id, const std::string& tracer_name) {
  return "tracer " + std::to_string(tracer_id) + " (" + tracer_name + ")";
}

void to_json(nlohmann::json& j, const StageSpan& s) {
  j = nlohmann::json{{"track", s.track}, {"stage", s.stage}, {"start_ms", s.start_ms}, {"ms", s.ms}};
}

void append_spans_ending_at(std::vector<StageSpan>& spans, const std::string& track, double end_ms,
                            const std::vector<ClockedStage>& stages, double not_before_ms) {
  std::vector<double> starts(stages.size());
  double at = end_ms;
  for (size_t i = stages.size(); i-- > 0;) starts[i] = at = std::max(not_before_ms, at - stages[i].ms);
  for (size_t i = 0; i < stages.size(); ++i)
    spans.push_back({track, stages[i].stage, starts[i], (i + 1 < stages.size() ? starts[i + 1] : end_ms) - starts[i]});
}

ScopedStage::ScopedStage(std::vector<StageSpan>& spans, std::string track, std::string stage)
    : spans_(&spans), start_(TimelineClock::now()) {
  span_.track = std::move(track);
  span_.stage = std::move(stage);
  span_.start_ms = timeline_ms(start_);
}

void ScopedStage::finish() {
  if (!spans_) return;
  span_.ms = std::chrono::duration<double, std::milli>(TimelineClock::now() - start_).count();
  spans_->push_back(std::move(span_));
  spans_ = nullptr;
}

ChromeTraceWriter::ChromeTraceWriter(const std::string& path) : path_(path), out_(path) {
  if (!out_) throw std::runtime_error(path + ": cannot write the trace file");
  out_ << "[\n";
  out_.flush();
}

ChromeTraceWriter::~ChromeTraceWriter() {
  out_ << "\n]\n";
}

int ChromeTraceWriter::thread_of(const std::string& track) {
  auto found = threads_.find(track);
  if (found != threads_.end()) return found->second;
  // The core first, then tracers in the order they appear; sort_index keeps that order on screen.
  const int tid = static_cast<int>(threads_.size()) + 1;
  threads_.emplace(track, tid);
  write({{"name", "thread_name"}, {"ph", "M"}, {"pid", 1}, {"tid", tid}, {"args", {{"name", track}}}});
  write({{"name", "thread_sort_index"}, {"ph", "M"}, {"pid", 1}, {"tid", tid}, {"args", {{"sort_index", tid}}}});
  return tid;
}

void ChromeTraceWriter::write(const nlohmann::json& event) {
  out_ << (events_ == 0 ? "" : ",\n") << event.dump();
  ++events_;
}

void ChromeTraceWriter::add(uint64_t frame, const std::vector<StageSpan>& spans) {
  if (events_ == 0) write({{"name", "process_name"}, {"ph", "M"}, {"pid", 1}, {"args", {{"name", "cohort"}}}});
  thread_of(kCoreTrack);
  for (const StageSpan& s : spans) {
    const int tid = thread_of(s.track);
    write({{"name", s.stage},
           {"cat", "frame"},
           {"ph", "X"},
           {"pid", 1},
           {"tid", tid},
           {"ts", s.start_ms * 1000.0},
           {"dur", s.ms * 1000.0},
           {"args", {{"frame", frame}}}});
  }
  out_.flush();
  if (!out_) throw std::runtime_error(path_ + ": writing the trace file failed");
}

}  // namespace cohort::core
