// What every tracer shares: its own copy of the scene (commit::TracerScene), brought up to date by
// applying commit buffers, and the two things its kernel needs from that copy each band: the frame
// parameters with the scene's counts, and a KSceneView over the arrays wherever the tracer keeps them.
#pragma once

#include <atomic>
#include <vector>

#include "cohort/commit/tracer_scene.h"
#include "cohort/core/tracer.h"
#include "cohort/kernel/scene_view.h"

namespace cohort::tracers {

class TracerBase : public core::Tracer {
 public:
  // Applies the commit to the scene copy, then hands the tracer what changed to upload.
  void apply(const commit::CommitBuffer& commit) final;

 protected:
  const commit::TracerScene& scene() const { return scene_; }
  // Whether a commit has been applied (and uploaded) yet: a band needs one.
  bool has_scene() const { return has_scene_; }

  // Brings the tracer's own copies (device buffers, acceleration structures) up to date with scene().
  // Until one upload has succeeded, changes arrive with full_resync set: there is nothing yet to patch.
  virtual void upload(const commit::ChangeSet& changes) = 0;
  // Whether the tracer runs the skinning routines (kernel/skinning.h) itself, on its device, for the
  // skins in ChangeSet::posed_skins; otherwise they run on the host while the commit is applied.
  virtual bool skins_on_device() const { return false; }

  // The band's parameters with the scene's light, instance and TLAS node counts filled in, and
  // K_LIGHTS_AUTO resolved by the scene's light density (core::resolve_light_sampling).
  KFrameParams frame_params(const core::BandJob& job) const;
  // The kernel's view of the scene copy itself, for tracers that trace from host memory.
  KSceneView host_scene_view(const KFrameParams& params) const;
  // Per instance (the scene's instance order), its object-to-world transform before the last applied
  // commit (12 floats each): the previous frame's, for object motion vectors (kernel/aux_outputs.h).
  // Instances are matched across commits by (entity, BLAS), since TLAS rebuilds reorder them; a new
  // one gets its current transform (no motion).
  const std::vector<float>& previous_transforms() const { return previous_transforms_; }
  // The joint pool (scene().joints' layout) before the last applied commit: the previous frame's pose of
  // every skinned character, for their motion vectors (kernel/aux_outputs.h's KAuxHistory).
  const std::vector<KJoint>& previous_joints() const { return previous_joints_; }

 private:
  void remember_previous_transforms(const std::vector<KInstance>& before);
  void remember_previous_joints(const std::vector<KSkin>& skins_before, std::vector<KJoint> joints_before);

  commit::TracerScene scene_;
  float light_density_ = 0.0f;          // core::light_density(scene_), kept with the light tree
  mutable std::atomic<kuint> logged_auto_{K_NONE};  // the choice K_LIGHTS_AUTO last logged
  std::vector<float> previous_transforms_;
  std::vector<KJoint> previous_joints_;
  bool has_scene_ = false;
};

}  // namespace cohort::tracers
