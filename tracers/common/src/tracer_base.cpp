#include "cohort/tracers/tracer_base.h"

#include <algorithm>
#include <cstdint>
#include <unordered_map>

#include <spdlog/spdlog.h>

#include "cohort/core/frame_defaults.h"
#include "cohort/core/light_sampling.h"

namespace cohort::tracers {

void TracerBase::apply(const commit::CommitBuffer& commit) {
  const std::vector<KInstance> before = scene_.instances;
  const std::vector<KSkin> skins_before = scene_.skins;
  std::vector<KJoint> joints_before = scene_.joints;
  commit::ChangeSet changes = commit::apply_commit(
      commit, scene_, skins_on_device() ? commit::Skinning::by_tracer : commit::Skinning::on_host);
  remember_previous_transforms(before);
  remember_previous_joints(skins_before, std::move(joints_before));
  if (!has_scene_) changes.full_resync = true;
  if (changes.full_resync || changes.light_tree || changes.emissive) light_density_ = core::light_density(scene_);
  upload(changes);
  has_scene_ = true;   // only now: after a failed first upload the next commit is sent whole again
}

void TracerBase::remember_previous_transforms(const std::vector<KInstance>& before) {
  auto key = [](const KInstance& inst) { return (static_cast<uint64_t>(inst.entity) << 32) | inst.blas; };
  std::unordered_map<uint64_t, const KInstance*> old;
  old.reserve(before.size());
  for (const KInstance& inst : before) old.emplace(key(inst), &inst);
  previous_transforms_.resize(scene_.instances.size() * 12);
  for (size_t i = 0; i < scene_.instances.size(); ++i) {
    const KInstance& inst = scene_.instances[i];
    auto found = old.find(key(inst));
    const float* from = found != old.end() ? found->second->object_to_world : inst.object_to_world;
    std::copy(from, from + 12, previous_transforms_.begin() + static_cast<std::ptrdiff_t>(12 * i));
  }
}

// The joint pool before the commit, where it still lines up with the new one (the same skins over the same
// joint ranges); otherwise the current joints: no skinned motion across a change of characters.
void TracerBase::remember_previous_joints(const std::vector<KSkin>& skins_before, std::vector<KJoint> joints_before) {
  bool same_layout = skins_before.size() == scene_.skins.size() && joints_before.size() == scene_.joints.size();
  for (size_t i = 0; same_layout && i < scene_.skins.size(); ++i)
    same_layout = skins_before[i].joint_offset == scene_.skins[i].joint_offset &&
                  skins_before[i].joint_count == scene_.skins[i].joint_count && skins_before[i].blas == scene_.skins[i].blas;
  previous_joints_ = same_layout ? std::move(joints_before) : scene_.joints;
}

KFrameParams TracerBase::frame_params(const core::BandJob& job) const {
  KFrameParams params = job.params;
  params.light_count = static_cast<kuint>(scene_.lights.size());
  params.instance_count = static_cast<kuint>(scene_.instances.size());
  params.tlas_node_count = static_cast<kuint>(scene_.tlas_nodes.size());
  params.light_node_count = static_cast<kuint>(scene_.light_nodes.size());
  params.emissive_count = static_cast<kuint>(scene_.emissive_triangles.size());
  params.light_sampling = core::resolve_light_sampling(job.params.light_sampling, light_density_);
  if (job.params.light_sampling == K_LIGHTS_AUTO && logged_auto_.exchange(params.light_sampling) != params.light_sampling)
    spdlog::info("light sampling auto: {} ({:.1f} lights in range of a light's centre on average, dense above {:.0f})",
                 core::light_sampling_name(params.light_sampling), light_density_, core::kDenseLightDensity);
  params.volume_light_begin = params.volume_light_end = 0u;
  for (size_t i = 0; i < scene_.lights.size(); ++i) {
    if (!(scene_.lights[i].flags & K_LIGHT_VOLUME_EFFECT)) continue;
    if (params.volume_light_end == 0u) params.volume_light_begin = static_cast<kuint>(i);
    params.volume_light_end = static_cast<kuint>(i + 1);
  }
  return params;
}

KSceneView TracerBase::host_scene_view(const KFrameParams& params) const {
  return k_scene_view(scene_.vertices.data(), scene_.vertex_colors.data(), scene_.triangles.data(), scene_.blas_nodes.data(), scene_.blases.data(),
                      scene_.instances.data(), scene_.tlas_nodes.data(), scene_.materials.data(),
                      scene_.textures.data(), scene_.texels.data(), scene_.lights.data(), scene_.light_nodes.data(),
                      scene_.emissive_triangles.data(), &params);
}

}  // namespace cohort::tracers
