#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "commands.h"

int main(int argc, char** argv) {
  // Diagnostics go to stderr, so stdout holds only what a command reports (info, bench tables).
  spdlog::set_default_logger(spdlog::stderr_color_mt("cohort"));
  spdlog::set_pattern("[%H:%M:%S.%e] [%^%l%$] %v");
  CLI::App app{
      "Cohort: a multi-device real-time path tracer for Doom 3 (idTech 4) scenes, after the Brigade\n"
      "renderer. Tracers (Embree on the CPU, OpenCL, CUDA) each render a band of rows; a balancer sizes\n"
      "the bands from measured times; frames are blended with adaptive convergence.\n"};
  app.name("cohort");
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("cohort ") + COHORT_VERSION);
  std::string log_level = "info";
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error or off")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}))
      ->capture_default_str();
  app.footer("Run 'cohort <command> --help' for a command's options. See README.md for examples.");

  int exit_code = cohort::app::kExitOk;
  cohort::app::add_info_command(app, exit_code);
  cohort::app::add_devices_command(app, exit_code);
  cohort::app::add_render_command(app, exit_code);
  cohort::app::add_play_command(app, exit_code);
  cohort::app::add_bench_command(app, exit_code);
  cohort::app::add_pack_command(app, exit_code);
  cohort::app::add_scenario_command(app, exit_code);
  cohort::app::add_node_command(app, exit_code);

  app.parse_complete_callback([&] { spdlog::set_level(spdlog::level::from_str(log_level)); });
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return cohort::app::kExitFailure;
  }
  return exit_code;
}
