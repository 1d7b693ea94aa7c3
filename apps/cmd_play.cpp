#include <iostream>

#include "commands.h"

namespace cohort::app {

void add_play_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("play", "Open a window and fly through a map rendered live on every tracer");
  auto map = std::make_shared<std::string>();
  cmd->add_option("map", *map, "map name or path")->required();
  cmd->callback([] {
    std::cerr << "cohort play: not implemented yet (issue 8)\n";
    std::exit(kExitUnavailable);
  });
}

}  // namespace cohort::app
