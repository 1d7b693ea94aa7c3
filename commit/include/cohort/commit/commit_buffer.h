// A commit buffer carries what changed in the scene since the frame a tracer last applied. The core
// fills one per tracer for frame N+1 while the tracer renders frame N from its own copy (Brigade,
// Fig. 7-8). The simplest commit is a full resync: the whole TracerScene.
#pragma once

#include <memory>

#include "cohort/commit/tracer_scene.h"

namespace cohort::commit {

class CommitBuffer {
 public:
  // A commit that replaces the tracer's whole scene.
  static CommitBuffer full(std::shared_ptr<const TracerScene> scene, uint64_t frame);

  bool is_full_resync() const { return full_ != nullptr; }
  uint64_t frame() const { return frame_; }
  const TracerScene* full_scene() const { return full_.get(); }

 private:
  std::shared_ptr<const TracerScene> full_;
  uint64_t frame_ = 0;
};

// Apply a commit to a tracer's scene copy; says what changed.
ChangeSet apply_commit(const CommitBuffer& commit, TracerScene& scene);

}  // namespace cohort::commit
