// Each subcommand of `cohort` lives in its own cmd_*.cpp and registers itself here. Its callback leaves
// the subcommand's exit code (kExit* below) in `exit_code`, which main() returns: no subcommand calls
// std::exit, so everything it made is destroyed in order.
#pragma once

#include <CLI/CLI.hpp>

namespace cohort::app {

void add_info_command(CLI::App& app, int& exit_code);
// `cohort devices`: the tracers' devices with kind and PCI bus id.
void add_devices_command(CLI::App& app, int& exit_code);
void add_render_command(CLI::App& app, int& exit_code);
void add_play_command(CLI::App& app, int& exit_code);
void add_bench_command(CLI::App& app, int& exit_code);
// `cohort bench devices`, under the bench command (called by add_bench_command).
void add_bench_devices_command(CLI::App& bench, int& exit_code);
void add_pack_command(CLI::App& app, int& exit_code);
void add_scenario_command(CLI::App& app, int& exit_code);
// `cohort node`: serve a remote tracer on an MPI rank above 0 (docs/cluster.md).
void add_node_command(CLI::App& app, int& exit_code);

// Exit codes shared by every subcommand.
constexpr int kExitOk = 0;
constexpr int kExitFailure = 1;
constexpr int kExitUsage = 2;
constexpr int kExitUnavailable = 3;   // the feature is not built in or the hardware is absent

}  // namespace cohort::app
