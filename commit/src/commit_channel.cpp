#include "cohort/commit/commit_channel.h"

#include <algorithm>
#include <utility>

namespace cohort::commit {

CommitChannel::CommitChannel(size_t byte_budget, std::shared_ptr<const TracerScene> initial, uint64_t frame)
    : byte_budget_(byte_budget) {
  pending_ = CommitBuffer::full(std::move(initial), frame);
  pending_taken_ = false;
}

void CommitChannel::publish(const CommitBuffer& frame_records, const Snapshot& snapshot) {
  std::lock_guard lock(mutex_);
  ++stats_.frames_published;
  if (!pending_taken_) ++stats_.frames_coalesced;
  pending_taken_ = false;
  if (resync_requested_) {
    pending_.reset_to_full(snapshot(), frame_records.frame());
    resync_requested_ = false;
    return;
  }
  pending_.merge(frame_records);
  if (pending_.bytes() > byte_budget_) {
    ++stats_.overflows;
    pending_.reset_to_full(snapshot(), frame_records.frame());
  }
  stats_.peak_pending_bytes = std::max(stats_.peak_pending_bytes, pending_.bytes());
}

const CommitBuffer& CommitChannel::begin_frame() {
  // The tracer is done with applying_ (same thread), so it can become the next pending buffer; keeping
  // it around reuses its capacity.
  take(applying_);
  return applying_;
}

void CommitChannel::take(CommitBuffer& into) {
  into.clear();
  std::lock_guard lock(mutex_);
  into.set_frame(pending_.frame());
  std::swap(into, pending_);
  pending_taken_ = true;
  ++stats_.commits_taken;
  if (into.is_full_resync()) ++stats_.full_resyncs_taken;
  stats_.last_bytes = into.bytes();
  stats_.last_records = into.record_count();
  stats_.total_bytes += into.bytes();
  stats_.total_records += into.record_count();
}

void CommitChannel::request_resync() {
  std::lock_guard lock(mutex_);
  resync_requested_ = true;
  ++stats_.resyncs_requested;
}

bool CommitChannel::has_pending() const {
  std::lock_guard lock(mutex_);
  return !pending_taken_;
}

bool CommitChannel::resync_requested() const {
  std::lock_guard lock(mutex_);
  return resync_requested_;
}

CommitStats CommitChannel::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

}  // namespace cohort::commit
