// One tracer's pair of commit buffers (Brigade, Fig. 7-8): the core folds each frame's records into the
// pending buffer while the tracer applies the other one; at its frame start the tracer swaps them.
//
// A tracer that skips frames simply finds several frames coalesced in the pending buffer, so it still
// converges to the core's state. The pending buffer has a byte budget: when it would grow past it, its
// records are dropped and replaced by a full resync to the core's current scene, and the stats count
// the overflow. Nothing is ever lost.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>

#include "cohort/commit/commit_buffer.h"

namespace cohort::commit {

struct CommitStats {
  uint64_t frames_published = 0;
  uint64_t frames_coalesced = 0;   // published into a pending buffer the tracer had not taken yet
  uint64_t commits_taken = 0;
  uint64_t full_resyncs_taken = 0; // the initial one, overflows and requested ones
  uint64_t overflows = 0;          // the pending buffer went over budget and became a full resync
  uint64_t resyncs_requested = 0;  // by the tracer (a commit that did not fit its scene)
  size_t last_bytes = 0;           // incremental bytes of the last commit taken
  size_t last_records = 0;
  uint64_t total_bytes = 0;
  uint64_t total_records = 0;
  size_t peak_pending_bytes = 0;
};

class CommitChannel {
 public:
  using Snapshot = std::function<std::shared_ptr<const TracerScene>()>;

  // The first commit the tracer takes is a full resync to `initial`.
  CommitChannel(size_t byte_budget, std::shared_ptr<const TracerScene> initial, uint64_t frame);

  // Core thread: fold one frame's records into the pending buffer. `snapshot` gives the core's scene
  // with those records applied; it is called (under the channel's lock) only for a full resync.
  void publish(const CommitBuffer& frame_records, const Snapshot& snapshot);

  // Tracer thread, at frame start: swap the buffers and return the one to apply, valid until the next
  // begin_frame on this channel. It is empty (frame() unchanged) when nothing changed.
  const CommitBuffer& begin_frame();
  // The same into a buffer the caller owns (cleared first; its capacity becomes the next pending
  // buffer's): for a core that hands a tracer its next commit while the tracer may still be applying the
  // one before (two frames in flight, core/renderer.h).
  void take(CommitBuffer& into);

  // Whether something was published since the last begin_frame (a full resync still to be taken, too).
  bool has_pending() const;

  // Tracer thread: the last commit could not be applied; the next publish sends a full resync.
  void request_resync();
  // Whether a resync was requested and no publish has answered it yet.
  bool resync_requested() const;

  CommitStats stats() const;
  size_t byte_budget() const { return byte_budget_; }

 private:
  const size_t byte_budget_;
  mutable std::mutex mutex_;
  CommitBuffer pending_;           // guarded by mutex_
  bool pending_taken_ = true;      // guarded by mutex_: nothing published since the last take
  bool resync_requested_ = false;  // guarded by mutex_
  CommitStats stats_;              // guarded by mutex_
  CommitBuffer applying_;          // tracer thread only
};

}  // namespace cohort::commit
