// Each subcommand of `cohort` lives in its own cmd_*.cpp and registers itself here.
#pragma once

#include <CLI/CLI.hpp>

namespace cohort::app {

void add_info_command(CLI::App& app);
void add_render_command(CLI::App& app);
void add_play_command(CLI::App& app);
void add_bench_command(CLI::App& app);
void add_pack_command(CLI::App& app);
void add_scenario_command(CLI::App& app);

// Exit codes shared by every subcommand.
constexpr int kExitOk = 0;
constexpr int kExitFailure = 1;
constexpr int kExitUsage = 2;
constexpr int kExitUnavailable = 3;   // the feature is not built in or the hardware is absent

}  // namespace cohort::app
