#include <algorithm>
#include <fstream>
#include <iostream>
#include <sstream>

#include <spdlog/spdlog.h>

#include "balance_bench.h"
#include "camera_path.h"
#include "commands.h"
#include "devices_bench.h"
#include "default_map.h"

namespace cohort::app {

namespace {

template <typename T>
std::vector<T> split_list(const std::string& text, const char* what) {
  std::vector<T> values;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (item.empty()) continue;
    std::istringstream parse(item);
    T v{};
    if (!(parse >> v) || !parse.eof()) throw CLI::ValidationError(what, "cannot read '" + item + "'");
    values.push_back(v);
  }
  return values;
}

std::string format_fraction(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

}  // namespace

void add_bench_command(CLI::App& app, int& exit_code) {
  auto* cmd = app.add_subcommand("bench", "Benchmarks (balancer efficiency: 'cohort bench balance'; device mixes: 'cohort bench devices')");
  cmd->require_subcommand(1);
  auto* balance = cmd->add_subcommand(
      "balance",
      "Idle time per balancer and tracer count while the camera spins (Brigade Table 1): idle % = time tracers\n"
      "wait for the slowest one / (tracers x frame time). Simulated tracers run on a virtual clock, so\n"
      "results are reproducible.");
  struct Args {
    std::string balancers, tracers = "2,3,4", speeds = "1", fixed_ms = "0", path = "both", real, json, plot;
    std::string scene = kTestMapFile;
    double noise = 0.02, row_work_error = 0.2, ms_per_cost = 0.05;
    bool row_work = true;
    std::string clock = "virtual";
    double time_scale = 1.0;
    int frames = 360, warmup = 5, rows = 720, frames_in_flight = 1;
    uint64_t seed = 1;
    balance::BalancerOptions options;
  };
  auto args = std::make_shared<Args>();
  balance->add_option("--balancers", args->balancers, "comma-separated balancers (default: all)");
  auto* tracers_option = balance->add_option("--tracers", args->tracers,
                                             "simulated tracer counts, comma-separated (default 2,3,4; with several "
                                             "--speeds or --fixed-ms: as many tracers as listed)");
  balance->add_option("--speeds", args->speeds, "relative speed per simulated tracer, cycled (e.g. 1,1,0.02)")->capture_default_str();
  balance->add_option("--fixed-ms", args->fixed_ms,
                      "fixed cost per band per simulated tracer in ms, cycled (e.g. 0,0,2): launch, upload and copy "
                      "overhead that does not shrink with the band")
      ->capture_default_str();
  balance->add_option("--ms-per-cost", args->ms_per_cost,
                      "simulated ms per cost unit at speed 1 (a 720-row frame is about 860 units: 43 ms alone at the default)")
      ->capture_default_str()->check(CLI::PositiveNumber);
  balance->add_option("--noise", args->noise, "relative standard deviation of each simulated band time")->capture_default_str();
  balance->add_option("--frames", args->frames, "frames per run")->capture_default_str()->check(CLI::PositiveNumber);
  balance->add_option("--warmup", args->warmup, "first frames left out of mean/worst")->capture_default_str()->check(CLI::NonNegativeNumber);
  balance->add_option("--rows", args->rows, "frame height in rows")->capture_default_str()->check(CLI::PositiveNumber);
  balance->add_option("--path", args->path, "camera spin: slow (2 deg/frame), fast (10 deg/frame) or both")
      ->check(CLI::IsMember({"slow", "fast", "both"}))->capture_default_str();
  balance->add_option("--seed", args->seed, "seed of the scene cost model and the noise")->capture_default_str();
  balance->add_option("--alpha", args->options.alpha, "Perfect Smooth blend weight of the new division (eq. 2)")->capture_default_str();
  balance->add_option("--robin-hood-units", args->options.robin_hood_units, "units Robin Hood moves per frame")->capture_default_str();
  balance->add_flag("!--no-row-work", args->row_work,
                    "simulated tracers do not report per-row work counts (Row Cost then learns row costs from band times only)");
  balance->add_option("--row-work-error", args->row_work_error, "relative error of the simulated per-row work counts")
      ->capture_default_str();
  balance->add_option("--clock", args->clock,
                      "simulated tracers: virtual (report times, fast and reproducible), sleep or spin (really take "
                      "the time x --time-scale; the renderer measures wall-clock time)")
      ->check(CLI::IsMember({"virtual", "sleep", "spin"}))->capture_default_str();
  balance->add_option("--time-scale", args->time_scale, "sleep/spin clocks: wall time per simulated ms")
      ->capture_default_str()->check(CLI::PositiveNumber);
  balance->add_option("--cost-rate", args->options.cost_rate, "Row Cost: how fast the per-unit cost map follows new times")
      ->capture_default_str();
  balance->add_option("--speed-rate", args->options.speed_rate, "Row Cost: how fast per-tracer speeds follow new times")
      ->capture_default_str();
  balance->add_option("--real", args->real,
                      "real tracers instead of simulated ones, e.g. embree,opencl:0 or cuda:all (they render --scene)");
  balance->add_option("--scene", args->scene, "map or scene pack the real tracers render")->capture_default_str();
  balance->add_option("--frames-in-flight", args->frames_in_flight,
                      "2: frame N+1 handed out before N is waited for (the Renderer's two frames in flight, through the "
                      "frame pipeline); compare the interval column on a sleep or spin clock")
      ->capture_default_str()
      ->check(CLI::Range(1, 2));
  balance->add_option("--json", args->json, "write every run (per-frame idle %) as JSON");
  balance->add_option("--plot", args->plot, "write a PNG chart of idle % per frame per balancer");
  balance->callback([args, tracers_option, &exit_code] {
    BalanceBenchConfig config;
    config.balancers = split_list<std::string>(args->balancers, "--balancers");
    config.tracer_counts = split_list<int>(args->tracers, "--tracers");
    config.speeds = split_list<double>(args->speeds, "--speeds");
    config.fixed_ms = split_list<double>(args->fixed_ms, "--fixed-ms");
    config.ms_per_cost = args->ms_per_cost;
    if (config.speeds.empty()) throw CLI::ValidationError("--speeds", "no speeds given");
    if (config.fixed_ms.empty()) throw CLI::ValidationError("--fixed-ms", "no fixed costs given");
    // A per-tracer list describes one mix of tracers: run that many unless counts were asked for.
    const size_t listed = std::max(config.speeds.size(), config.fixed_ms.size());
    if (tracers_option->count() == 0 && listed > 1) config.tracer_counts = {static_cast<int>(listed)};
    config.noise = args->noise;
    config.row_work = args->row_work;
    config.clock = args->clock;
    config.time_scale = args->time_scale;
    config.row_work_error = args->row_work_error;
    config.frames = args->frames;
    config.warmup = args->warmup;
    config.rows = args->rows;
    config.seed = args->seed;
    config.frames_in_flight = args->frames_in_flight;
    config.balancer_options = args->options;
    config.real = split_list<std::string>(args->real, "--real");
    config.real_scene = args->scene;
    config.paths = args->path == "both" ? std::vector<std::string>{"slow", "fast"} : std::vector<std::string>{args->path};
    const std::vector<std::string> known = balance::balancer_names();
    std::string known_list;
    for (const std::string& n : known) known_list += (known_list.empty() ? "" : ", ") + n;
    for (const std::string& b : config.balancers)
      if (std::find(known.begin(), known.end(), b) == known.end())
        throw CLI::ValidationError("--balancers", "unknown balancer '" + b + "' (known: " + known_list + ")");
    for (int c : config.tracer_counts)
      if (c < 1) throw CLI::ValidationError("--tracers", "counts must be >= 1");
    for (double s : config.speeds)
      if (!(s > 0.0)) throw CLI::ValidationError("--speeds", "speeds must be > 0");
    for (double f : config.fixed_ms)
      if (!(f >= 0.0)) throw CLI::ValidationError("--fixed-ms", "fixed costs must be >= 0");

    std::vector<BalanceBenchRun> runs;
    try {
      runs = run_balance_bench(config);
    } catch (const std::exception& e) {  // unknown names (invalid_argument) as well as missing devices
      spdlog::error("cohort bench balance: {}", e.what());
      exit_code = config.real.empty() ? kExitFailure : kExitUnavailable;
      return;
    }
    std::cout << (config.real.empty() ? "simulated tracers, speeds " + args->speeds + ", fixed ms " + args->fixed_ms +
                                            ", " + format_fraction(config.ms_per_cost) + " ms per cost unit, noise " + format_fraction(config.noise) +
                                            (config.row_work ? ", per-row work counts with error " + format_fraction(config.row_work_error)
                                                             : ", no per-row work counts")
                                      : "real tracers: " + args->real)
              << (config.real.empty() ? ", " + config.clock + " clock" : "") << ", " << config.frames << " frames (first " << config.warmup << " not counted), " << config.rows << " rows\n"
              << balance_bench_table(runs);
    if (!args->json.empty()) {
      std::ofstream out(args->json);
      out << balance_bench_json(config, runs).dump(1) << "\n";
      if (!out) throw std::runtime_error("cannot write " + args->json);
      std::cout << "wrote " << args->json << "\n";
    }
    if (!args->plot.empty()) {
      write_balance_plot(args->plot, runs);
      std::cout << "wrote " << args->plot << "\n";
    }
  });

  add_bench_devices_command(*cmd, exit_code);
}

void add_bench_devices_command(CLI::App& bench, int& exit_code) {
  auto* devices = bench.add_subcommand(
      "devices",
      "Does every device add speed? The same camera path on each tracer alone and on mixes of them: median and\n"
      "p95 wall ms per frame, fps, idle % and scaling efficiency = (1/T_mix) / sum of (1/T_alone) over the mix.\n"
      "Default mixes: Embree and every GPU alone, each GPU with Embree, all GPUs without and with Embree.\n"
      "Remote tracers (mpi:RANK, under mpirun with `cohort node` on that rank) also report bytes per frame and\n"
      "the band round trip (docs/cluster.md).");
  struct Args {
    std::vector<std::string> mixes;
    std::string json, plot;
    DevicesBenchConfig config;
  };
  auto args = std::make_shared<Args>();
  devices->add_option("--mix", args->mixes, "a tracer mix, e.g. embree,cuda:0 (repeat for several; default: see above)");
  devices->add_option("--scene", args->config.scene, "map or scene pack to render")->capture_default_str();
  devices->add_option("--width", args->config.width, "image width")->capture_default_str()->check(CLI::PositiveNumber);
  devices->add_option("--height", args->config.height, "image height")->capture_default_str()->check(CLI::PositiveNumber);
  devices->add_option("--frames", args->config.frames, "frames per mix")->capture_default_str()->check(CLI::PositiveNumber);
  devices->add_option("--warmup", args->config.warmup, "first frames not counted")->capture_default_str()->check(CLI::NonNegativeNumber);
  devices->add_option("--camera-path", args->config.camera_path, "spin or orbit, -slow or -fast, from the player start")
      ->capture_default_str()
      ->check(camera_path_error);
  devices->add_option("--balancer", args->config.balancer, "row balancer")
      ->capture_default_str()->check(CLI::IsMember(balance::balancer_names()));
  devices->add_option("--frames-in-flight", args->config.frames_in_flight,
                      "0: frame by frame (each frame handed out, waited for and merged before the next: wall ms is "
                      "that frame); 1 or 2: through the frame pipeline as `cohort render` runs it (the next frame "
                      "announced at hand-out, with 2 handed out before the one before is back): wall ms is the "
                      "interval between frames")
      ->capture_default_str()
      ->check(CLI::Range(0, 2));
  devices->add_option("--json", args->json, "write every run (per-frame wall ms) as JSON");
  devices->add_option("--plot", args->plot, "write a PNG bar chart of median wall ms per mix");
  devices->callback([args, &exit_code] {
    DevicesBenchConfig config = args->config;
    if (config.warmup >= config.frames) throw CLI::ValidationError("--warmup", "must be less than --frames");
    for (const std::string& mix : args->mixes) {
      std::vector<std::string> names = split_list<std::string>(mix, "--mix");
      if (names.empty()) throw CLI::ValidationError("--mix", "empty mix");
      config.mixes.push_back(std::move(names));
    }
    std::vector<DevicesBenchRun> runs;
    try {
      runs = run_devices_bench(config);
    } catch (const std::exception& e) {  // a tracer not built or a device absent
      spdlog::error("cohort bench devices: {}", e.what());
      exit_code = kExitUnavailable;
      return;
    }
    std::cout << config.scene << ", " << config.width << "x" << config.height << ", " << config.camera_path << ", "
              << config.frames << " frames (first " << config.warmup << " not counted), balancer " << config.balancer
              << (config.frames_in_flight == 0
                      ? ", frame by frame\n"
                      : ", through the frame pipeline with " + std::to_string(config.frames_in_flight) +
                            " in flight (ms: the interval between frames)\n")
              << devices_bench_table(runs);
    if (!args->json.empty()) {
      std::ofstream out(args->json);
      out << devices_bench_json(config, runs).dump(1) << "\n";
      if (!out) throw std::runtime_error("cannot write " + args->json);
      std::cout << "wrote " << args->json << "\n";
    }
    if (!args->plot.empty()) {
      write_devices_plot(args->plot, runs);
      std::cout << "wrote " << args->plot << "\n";
    }
  });
}

}  // namespace cohort::app
