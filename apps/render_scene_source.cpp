#include "render_scene_source.h"

#include <filesystem>
#include <stdexcept>

#include <spdlog/spdlog.h>

#include "cohort/core/gpu_scene.h"
#include "cohort/core/scene_pack.h"
#include "cohort/scene/map_loader.h"

namespace cohort::app {

RenderScene load_render_scene(const std::string& path, const std::vector<std::string>& bases) {
  if (std::filesystem::is_regular_file(path) && core::is_scene_pack(path)) {
    core::PackedScene pack = core::read_scene_pack(path);
    RenderScene out;
    out.name = pack.map_name;
    out.player_start = glm::vec3(pack.player_start[0], pack.player_start[1], pack.player_start[2]);
    out.player_yaw = pack.player_yaw;
    out.tracer_scene = std::make_shared<const commit::TracerScene>(std::move(pack.tracer_scene));
    return out;
  }
  scene::Vfs vfs;
  for (const std::string& base : bases) vfs.add_search_path(base);
  scene::LoadReport report;
  scene::Scene loaded = scene::load_map(vfs, path, &report);
  for (size_t i = 0; i < loaded.warnings.size() && i < 10; ++i) spdlog::warn("{}", loaded.warnings[i]);
  if (loaded.warnings.size() > 10) spdlog::warn("... {} more warnings (cohort info lists them)", loaded.warnings.size() - 10);
  RenderScene out;
  out.name = loaded.name;
  out.player_start = loaded.player_start;
  out.player_yaw = loaded.player_yaw;
  out.world = std::make_shared<scene::RenderWorld>(std::move(loaded));
  return out;
}

}  // namespace cohort::app
