#include <iostream>

#include "commands.h"

namespace cohort::app {

void add_render_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("render", "Render frames headless on the chosen tracers and write images and a "
                                           "JSON of per-frame stats");
  auto map = std::make_shared<std::string>();
  cmd->add_option("map", *map, "map name or path")->required();
  cmd->callback([] {
    std::cerr << "cohort render: not implemented yet (issues 6-8)\n";
    std::exit(kExitUnavailable);
  });
}

}  // namespace cohort::app
