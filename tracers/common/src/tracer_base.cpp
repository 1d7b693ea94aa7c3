#include "cohort/tracers/tracer_base.h"

#include <algorithm>
#include <cstdint>
#include <unordered_map>

namespace cohort::tracers {

void TracerBase::apply(const commit::CommitBuffer& commit) {
  const std::vector<KInstance> before = scene_.instances;
  commit::ChangeSet changes = commit::apply_commit(
      commit, scene_, skins_on_device() ? commit::Skinning::by_tracer : commit::Skinning::on_host);
  remember_previous_transforms(before);
  if (!has_scene_) changes.full_resync = true;
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

KFrameParams TracerBase::frame_params(const core::BandJob& job) const {
  KFrameParams params = job.params;
  params.light_count = static_cast<kuint>(scene_.lights.size());
  params.instance_count = static_cast<kuint>(scene_.instances.size());
  params.tlas_node_count = static_cast<kuint>(scene_.tlas_nodes.size());
  params.light_node_count = static_cast<kuint>(scene_.light_nodes.size());
  params.emissive_count = static_cast<kuint>(scene_.emissive_triangles.size());
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
