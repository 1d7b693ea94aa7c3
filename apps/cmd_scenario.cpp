// `cohort record-scenario <map> --frames N --out FILE`: drive the test map through the RenderWorld
// API (door, fan, flickering light, flashlight on a camera path) and record the delta stream that
// `cohort render --replay FILE` plays back.
#include <filesystem>
#include <iostream>

#include <spdlog/spdlog.h>

#include "cohort/scene/map_loader.h"
#include "cohort/scene/render_world_stream.h"
#include "cohort/scene/scenario.h"
#include "commands.h"
#include "default_map.h"

namespace cohort::app {
namespace {

struct ScenarioArgs {
  std::string map;
  std::vector<std::string> bases;
  int frames = 240;
  double fps = 60.0;
  std::string out = "out/scenario.cds";
};

int run_record_scenario(const ScenarioArgs& args) {
  try {
    scene::Vfs vfs;
    for (const std::string& base : bases_or_test_map(args.bases)) vfs.add_search_path(base);
    scene::RenderWorld world(scene::load_map(vfs, args.map));
    std::filesystem::path out(args.out);
    if (out.has_parent_path()) std::filesystem::create_directories(out.parent_path());
    scene::ScenarioOptions options;
    options.frames_per_second = args.fps;
    // Check the names before creating the file, so a wrong map leaves nothing behind.
    { scene::Scenario check(world, options); }
    scene::Recorder recorder(world, out, args.map);
    scene::run_scenario(recorder, args.frames, options);
    recorder.finish();
    std::cout << "recorded " << recorder.frames_written() << " frames of '" << world.scene().name << "' to " << args.out
              << " (" << recorder.bytes_written() << " bytes)\n";
    return kExitOk;
  } catch (const std::exception& e) {  // scene::ScenarioError (entities the map lacks) included
    spdlog::error("cohort record-scenario: {}", e.what());
    return kExitFailure;
  }
}

}  // namespace

void add_scenario_command(CLI::App& app, int& exit_code) {
  auto* cmd = app.add_subcommand("record-scenario",
                                 "Drive the test map through the scene-delta API (door_main opens, fan_spin spins, "
                                 "light_flicker flickers, a flashlight follows the camera path) and record the "
                                 "delta stream for `cohort render --replay`");
  auto args = std::make_shared<ScenarioArgs>();
  cmd->add_option("map", args->map, "a .map file path, or a map name looked up under maps/ in the --base folders "
                                    "(e.g. testmap)")->required();
  cmd->add_option("--base", args->bases, "game folder with loose files and .pk4 archives; repeat it "
                                         "(default: assets/testmap)");
  cmd->add_option("--frames", args->frames, "frames to record")->check(CLI::Range(1, 1000000))->capture_default_str();
  cmd->add_option("--fps", args->fps, "frames per second of scenario time")->check(CLI::Range(1.0, 1000.0))
      ->capture_default_str();
  cmd->add_option("--out", args->out, "delta stream file to write (format: docs/delta-stream.md)")
      ->capture_default_str();
  cmd->callback([args, &exit_code] { exit_code = run_record_scenario(*args); });
}

}  // namespace cohort::app
