#include <iostream>

#include "commands.h"

namespace cohort::app {

void add_bench_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("bench", "Benchmarks (balancer efficiency: 'cohort bench balance')");
  cmd->require_subcommand(1);
  auto* balance = cmd->add_subcommand("balance", "Idle time per balancer and tracer count (Brigade Table 1)");
  balance->callback([] {
    std::cerr << "cohort bench balance: not implemented yet (issue 7)\n";
    std::exit(kExitUnavailable);
  });
}

}  // namespace cohort::app
