#include "render_scene_source.h"

#include <filesystem>
#include <stdexcept>

#include "cohort/core/scene_pack.h"

namespace cohort::app {

RenderScene load_render_scene(const std::string& path) {
  if (!std::filesystem::exists(path)) throw std::runtime_error(path + ": no such file");
  if (core::is_scene_pack(path)) {
    core::PackedScene pack = core::read_scene_pack(path);
    RenderScene out;
    out.name = pack.map_name;
    out.player_start = glm::vec3(pack.player_start[0], pack.player_start[1], pack.player_start[2]);
    out.player_yaw = pack.player_yaw;
    out.tracer_scene = std::make_shared<const commit::TracerScene>(std::move(pack.tracer_scene));
    return out;
  }
  throw std::runtime_error(path + ": not a scene pack; rendering .map files directly needs the map loader "
                                  "(issue 3) - make a pack with `cohort pack` meanwhile");
}

}  // namespace cohort::app
