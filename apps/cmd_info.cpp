#include <iostream>

#include "commands.h"

namespace cohort::app {

void add_info_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("info", "Load a map and print what it contains (areas, triangles, materials, "
                                         "textures, lights by type, entities, warnings)");
  auto map = std::make_shared<std::string>();
  cmd->add_option("map", *map, "map name or path (e.g. assets/testmap/maps/testmap.map)")->required();
  cmd->callback([map] {
    std::cerr << "cohort info: map loading is not implemented yet (issue 3)\n";
    std::exit(kExitUnavailable);
  });
}

}  // namespace cohort::app
