#include "cohort/core/frame_pipeline.h"

#include <cstdlib>
#include <stdexcept>
#include <string>

#include <spdlog/spdlog.h>

namespace cohort::core {

FramePipeline::~FramePipeline() {
  // Both frames may be in flight (one handed out ahead): each writes image_ when it is merged.
  for (std::optional<InFlight>* frame : {&in_flight_, &ahead_}) {
    if (!*frame) continue;
    try {
      renderer_.finish_frame();
    } catch (const std::exception& e) {
      spdlog::warn("frame pipeline: a frame in flight failed while shutting down: {}", e.what());
    }
  }
}

FramePipeline::Delivered FramePipeline::delivered(InFlight frame, FrameStats stats) {
  stats.stages.insert(stats.stages.begin(), std::make_move_iterator(frame.preparation.begin()),
                      std::make_move_iterator(frame.preparation.end()));
  return {std::move(frame.job), std::move(stats)};
}

std::optional<FramePipeline::Delivered> FramePipeline::push(const BandJob& job, std::vector<StageSpan> preparation) {
  return push(job, std::move(preparation), PrepareNext());
}

std::optional<FramePipeline::Delivered> FramePipeline::push(const BandJob& job, std::vector<StageSpan> preparation,
                                                            const PrepareNext& prepare_next) {
  if (renderer_.frames_in_flight() == 2) return push_two_in_flight(job, std::move(preparation), prepare_next);
  std::optional<InFlight> previous = std::move(in_flight_);
  in_flight_.reset();
  std::optional<FrameStats> stats;
  if (previous) {
    // Known now, handed out only once the frame in flight is back: tracers that can start on it early may.
    renderer_.announce_frame(job);
    stats = renderer_.wait_frame();
  }
  try {
    renderer_.begin_frame(job, image_);
  } catch (...) {
    if (previous) renderer_.merge_frame(*stats);  // leave the Renderer ready for the next begin
    throw;
  }
  in_flight_ = InFlight{job, std::move(preparation)};
  prepare_and_announce(prepare_next, [&] {
    if (previous) renderer_.merge_frame(*stats);
  });
  if (!previous) return std::nullopt;
  renderer_.merge_frame(*stats);
  return delivered(std::move(*previous), std::move(*stats));
}

std::optional<FramePipeline::Delivered> FramePipeline::push_two_in_flight(const BandJob& job,
                                                                          std::vector<StageSpan> preparation,
                                                                          const PrepareNext& prepare_next) {
  // Handed out at once, while the frame before still renders: each worker queues it behind that frame's
  // band and starts it the moment that band is done (Renderer: frames_in_flight 2). Or handed out already,
  // by the push before, as soon as the frame before that was merged (below).
  std::optional<InFlight> previous = std::move(in_flight_);
  in_flight_.reset();
  if (ahead_) {
    if (ahead_->job.params.frame_index != job.params.frame_index) {
      in_flight_ = std::move(previous);
      throw std::logic_error("FramePipeline::push: frame " + std::to_string(job.params.frame_index) +
                             " pushed, but prepare_next returned frame " +
                             std::to_string(ahead_->job.params.frame_index) + ", which is handed out already");
    }
    in_flight_ = InFlight{std::move(ahead_->job), std::move(preparation)};
    ahead_.reset();
  } else {
    try {
      renderer_.begin_frame(job, image_);
    } catch (...) {
      in_flight_ = std::move(previous);  // still the Renderer's frame in flight
      throw;
    }
    in_flight_ = InFlight{job, std::move(preparation)};
  }
  // The announcement is for workers with no job queued when they end this one (remote tracers start on it
  // ahead). Should the preparation fail, one frame stays in flight, as push() promises.
  const std::optional<BandJob> next = prepare_and_announce(prepare_next, [&] {
    if (previous) renderer_.finish_frame();
  });
  if (!previous) return std::nullopt;
  FrameStats stats = renderer_.wait_frame();
  renderer_.merge_frame(stats);
  // The slot the frame before was merged from is free: the next frame, prepared above, is handed out now,
  // before the caller post-processes the frame returned here (blend, tone map, output), so that a tracer
  // whose band ends during that post finds its next job queued (docs/balancing.md, "The next frame handed
  // out as soon as a slot frees"). Should it fail (every tracer still busy with late work), the next push
  // hands it out as before, and fails there if it still must.
  if (next && hands_out_ahead()) {
    try {
      renderer_.begin_frame(*next, image_);
      ahead_ = InFlight{*next, {}};
    } catch (const std::exception& e) {
      spdlog::debug("frame pipeline: frame {} not handed out ahead: {}", next->params.frame_index, e.what());
    }
  }
  return delivered(std::move(*previous), std::move(stats));
}

std::optional<BandJob> FramePipeline::prepare_and_announce(const PrepareNext& prepare_next,
                                                           const std::function<void()>& restore) {
  if (!prepare_next) return std::nullopt;
  std::optional<BandJob> next;
  try {
    next = prepare_next();
  } catch (...) {
    restore();
    throw;
  }
  if (next) renderer_.announce_frame(*next);
  return next;
}

bool FramePipeline::hands_out_ahead() {
  const char* ahead = std::getenv("COHORT_HAND_OUT_AHEAD");
  return !(ahead && std::string(ahead) == "0");
}

bool FramePipeline::announces_at_hand_out() {
  const char* early = std::getenv("COHORT_EARLY_ANNOUNCE");
  return !(early && std::string(early) == "0");
}

std::optional<FramePipeline::Delivered> FramePipeline::drain() {
  if (!in_flight_) return std::nullopt;
  InFlight frame = std::move(*in_flight_);
  in_flight_.reset();
  // A frame handed out ahead and never pushed is the next to drain.
  if (ahead_) {
    in_flight_ = std::move(ahead_);
    ahead_.reset();
  }
  FrameStats stats = renderer_.finish_frame();
  return delivered(std::move(frame), std::move(stats));
}

}  // namespace cohort::core
