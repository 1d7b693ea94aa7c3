#include "real_tracers.h"

#include <spdlog/spdlog.h>

#include "cohort/core/view.h"
#include "cohort/core/world_sync.h"
#include "cohort/tracers/tracer_registry.h"
#include "render_scene_source.h"

namespace cohort::app {

RealTracers make_real_tracers(const std::vector<std::string>& names, const std::string& scene_path) {
  std::string list;
  for (const std::string& n : names) list += (list.empty() ? "" : ",") + n;
  RealTracers out;
  out.tracers = tracers::make_tracers(list);
  RenderScene scene = load_render_scene(scene_path, {});
  // A scene pack comes compiled; a map is compiled by WorldSync as `cohort render` does (without it the
  // commit below would carry no scene and every tracer would render an empty one).
  std::shared_ptr<const commit::TracerScene> compiled = scene.tracer_scene;
  if (!compiled) compiled = core::WorldSync(*scene.world).snapshot();
  auto commit = commit::CommitBuffer::full(compiled, 1);
  for (auto& t : out.tracers) {
    spdlog::info("bench: {} loads {}", t->name(), scene.name);
    t->apply(commit);
  }
  out.eye = scene.player_start + glm::vec3(0.0f, 0.0f, core::kPlayerEyeHeight);
  out.yaw = scene.player_yaw;
  return out;
}

}  // namespace cohort::app
