#include <iostream>

#include <spdlog/spdlog.h>

#include "cohort/scene/map_loader.h"
#include "commands.h"
#include "default_map.h"

namespace cohort::app {

namespace {

int run_info(const std::string& map, std::vector<std::string> bases, size_t max_warnings) {
  scene::Vfs vfs;
  scene::LoadReport report;
  scene::Scene loaded;
  try {
    for (const std::string& base : bases) vfs.add_search_path(base);
    loaded = scene::load_map(vfs, map, &report);
  } catch (const std::exception& e) {  // scene::ParseError included
    spdlog::error("cohort info: {}", e.what());
    return kExitFailure;
  }
  // Light kinds come from the light material (fogLight / blendLight / ambientLight); no material: normal.
  int kinds[4] = {0, 0, 0, 0};
  for (const scene::Light& light : loaded.lights) {
    scene::LightKind kind = scene::LightKind::Normal;
    if (light.material >= 0 && size_t(light.material) < loaded.materials.size())
      kind = loaded.materials[size_t(light.material)].light_kind;
    ++kinds[static_cast<int>(kind)];
  }
  std::cout << "map        " << loaded.name << "\n"
            << "  .map     " << report.map_file << "\n"
            << "  .proc    " << report.proc_file << "\n"
            << "areas      " << report.areas << " (" << report.portals << " portals, " << report.nodes
            << " nodes, " << report.shadow_models_skipped << " shadow models skipped)\n"
            << "triangles  " << report.world_triangles << " world, " << report.entity_triangles << " in entities ("
            << report.inline_models << " inline models)\n"
            << "materials  " << report.materials_used << " used (" << report.materials_missing << " missing), "
            << report.materials_declared << " declared in " << report.material_files << " .mtr files\n"
            << "  glowing  " << report.emitters << ": " << report.emitting_surfaces
            << " opaque (light sources for next-event estimation), " << report.emitters - report.emitting_surfaces
            << " blended layers (seen, not sampled)\n"
            << "  sky      " << report.skies << " (cube maps seen by rays that reach them), environment maps "
            << report.environment_maps << " (reflect/normal), noSelfShadow " << report.no_self_shadow << "\n"
            << "textures   " << report.images_loaded + report.images_placeholder << " (" << report.images_placeholder
            << " placeholders)\n"
            << "lights     " << loaded.lights.size() << ": " << report.lights_point << " point, "
            << report.lights_projected << " projected, " << report.lights_parallel << " parallel\n"
            << "  kinds    " << kinds[0] << " normal, " << kinds[1] << " fog, " << kinds[2] << " blend, " << kinds[3]
            << " ambient\n"
            << "entities   " << loaded.entities.size() << "\n";
  for (const auto& [classname, count] : report.entities_by_class)
    std::cout << "  " << classname << " " << count << "\n";
  std::cout << "decls      " << report.entity_defs << " entityDefs, " << report.model_defs << " modelDefs, "
            << report.skins << " skins in " << report.def_files << " .def/.skin files\n"
            << "models     " << report.model_files_loaded << " model meshes loaded (one per model file and skin)\n"
            << "unresolved " << report.unresolved_classes.size() << " classes, " << report.unresolved_models.size()
            << " models\n";
  for (const auto& [classname, count] : report.unresolved_classes)
    std::cout << "  class " << classname << " (" << count << " entities)\n";
  for (const auto& [model, count] : report.unresolved_models)
    std::cout << "  model " << model << " (" << count << " entities)\n";
  std::cout << "player     (" << loaded.player_start.x << " " << loaded.player_start.y << " " << loaded.player_start.z
            << ") yaw " << loaded.player_yaw << "\n"
            << "warnings   " << report.warnings.size() << "\n";
  for (size_t i = 0; i < report.warnings.size() && i < max_warnings; ++i)
    std::cout << "  " << report.warnings[i] << "\n";
  if (report.warnings.size() > max_warnings)
    std::cout << "  ... " << report.warnings.size() - max_warnings << " more (--max-warnings)\n";
  return kExitOk;
}

}  // namespace

void add_info_command(CLI::App& app, int& exit_code) {
  auto* cmd = app.add_subcommand("info", "Load a map and print what it contains (areas, triangles, materials, "
                                         "textures, lights by type, entities, warnings)");
  auto map = std::make_shared<std::string>();
  auto bases = std::make_shared<std::vector<std::string>>();
  auto max_warnings = std::make_shared<size_t>(50);
  cmd->add_option("map", *map, "a .map file path, or a map name looked up under maps/ in the --base folders "
                               "(e.g. testmap)")->required();
  cmd->add_option("--base", *bases, "game folder with loose files and .pk4 archives; repeat it, later folders "
                                    "override earlier ones (default: assets/testmap)");
  cmd->add_option("--max-warnings", *max_warnings, "how many warnings to print");
  cmd->callback([map, bases, max_warnings, &exit_code] {
    exit_code = run_info(*map, bases_or_test_map(*bases), *max_warnings);
  });
}

}  // namespace cohort::app
