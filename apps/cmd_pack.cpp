// `cohort pack <map> --out FILE`: compile a map once into a self-contained scene pack (docs/scene-pack.md)
// that loads with no image library, e.g. on the GPU machine.
#include <chrono>
#include <filesystem>
#include <iostream>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "cohort/core/gpu_scene.h"
#include "cohort/core/scene_pack.h"
#include "cohort/scene/map_loader.h"
#include "commands.h"

namespace cohort::app {
namespace {

struct PackArgs {
  std::string map;
  std::string out;
  std::vector<std::string> bases;
};

int run_pack(const PackArgs& a) {
  using Clock = std::chrono::steady_clock;
  auto t0 = Clock::now();
  scene::Vfs vfs;
  for (const std::string& base : a.bases) vfs.add_search_path(base);
  scene::LoadReport report;
  scene::Scene loaded = scene::load_map(vfs, a.map, &report);
  for (const std::string& w : loaded.warnings) spdlog::warn("{}", w);
  auto t1 = Clock::now();
  core::CompiledScene compiled = core::compile_scene(loaded);
  auto t2 = Clock::now();

  core::PackedScene pack;
  pack.map_name = loaded.name;
  pack.tracer_scene = std::move(compiled.tracer_scene);
  pack.blas_of_mesh = std::move(compiled.blas_of_mesh);
  pack.world_blas = compiled.world_blas;
  for (const KInstance& inst : pack.tracer_scene.instances)
    pack.instance_names.push_back(inst.entity < loaded.entities.size() ? loaded.entities[inst.entity].name : "world");
  pack.player_start[0] = loaded.player_start.x;
  pack.player_start[1] = loaded.player_start.y;
  pack.player_start[2] = loaded.player_start.z;
  pack.player_yaw = loaded.player_yaw;
  std::filesystem::path out(a.out);
  if (out.has_parent_path()) std::filesystem::create_directories(out.parent_path());
  core::write_scene_pack(out, pack);
  auto t3 = Clock::now();
  auto ms = [](auto d) { return std::chrono::duration<double, std::milli>(d).count(); };
  const auto& s = pack.tracer_scene;
  std::cout << fmt::format(
      "{}: {} triangles, {} BLASes, {} instances, {} materials, {} textures ({:.1f} MB of texels with mips), {} lights\n"
      "load {:.0f} ms, compile {:.0f} ms, write {:.0f} ms -> {} ({:.1f} MB)\n",
      pack.map_name, s.triangles.size(), s.blases.size(), s.instances.size(), s.materials.size(), s.textures.size(),
      s.texels.size() * 4.0 / 1e6, s.lights.size(), ms(t1 - t0), ms(t2 - t1), ms(t3 - t2), out.string(),
      std::filesystem::file_size(out) / 1e6);
  return kExitOk;
}

}  // namespace

void add_pack_command(CLI::App& app, int& exit_code) {
  auto* cmd = app.add_subcommand("pack", "Compile a map into one self-contained scene pack (geometry, BVHs, materials, "
                                         "lights, decoded mip-mapped textures) that loads without an image library");
  auto a = std::make_shared<PackArgs>();
  cmd->add_option("map", a->map, "a .map path, a game path (maps/x.map) or a bare map name")->required();
  cmd->add_option("-o,--out", a->out, "pack file to write (.cpk)")->required();
  cmd->add_option("--base", a->bases, "game folder(s) to search, loose files and .pk4s (default: the map's own base)");
  cmd->callback([a, &exit_code] {
    try {
      exit_code = run_pack(*a);
    } catch (const std::exception& e) {
      spdlog::error("cohort pack: {}", e.what());
      exit_code = kExitFailure;
    }
  });
}

}  // namespace cohort::app
