#include "cohort/commit/commit_buffer.h"

namespace cohort::commit {

CommitBuffer CommitBuffer::full(std::shared_ptr<const TracerScene> scene, uint64_t frame) {
  CommitBuffer c;
  c.full_ = std::move(scene);
  c.frame_ = frame;
  return c;
}

ChangeSet apply_commit(const CommitBuffer& commit, TracerScene& scene) {
  ChangeSet changes;
  if (commit.is_full_resync()) {
    scene = *commit.full_scene();
    changes.full_resync = true;
  }
  scene.version = commit.frame();
  return changes;
}

}  // namespace cohort::commit
