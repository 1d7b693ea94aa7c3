// Frame time against the light count on the same geometry, per light-sampling mode: the light tree
// (the default), the all-lights pick and every light. N point lights are scattered (seeded) over the
// world's bounding box, each sized so that about --overlap of them reach an average point, as in a map
// where more lights light more rooms rather than the same spot; --radius R fixes their size instead.
//
//   bench_lights [scene.pack | map] [options]   (bench_lights --help lists them)
// Default: the generated test map (assets/testmap) from the player start, Embree, 320x180, 1 spp, 1 bounce.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "cohort/core/frame_defaults.h"
#include "cohort/core/gpu_scene.h"
#include "cohort/core/light_sampling.h"
#include "cohort/core/scene_pack.h"
#include "cohort/core/view.h"
#include "cohort/scene/map_loader.h"
#include "cohort/tracers/tracer_registry.h"

using namespace cohort;

namespace {

struct Config {
  std::string scene = std::string(COHORT_SOURCE_DIR) + "/assets/testmap/maps/testmap.map";
  std::string tracer = "embree";
  std::vector<int> counts = {8, 64, 256, 1024};
  std::vector<std::string> modes = {"tree", "all", "every"};
  int width = 320, height = 180, spp = 1, bounces = 1, repeats = 3;
  float overlap = 4.0f, radius = 0.0f;
  std::string json = "bench_lights.json";
};

Config parse(int argc, char** argv) {
  Config c;
  CLI::App app{"Frame time against the light count on the same geometry, per light-sampling mode (tree, all, "
               "every): N point lights scattered over the world's box, sized so that about --overlap reach an "
               "average point. Prints a table and writes JSON."};
  app.add_option("scene", c.scene, "scene pack or .map (default: the generated test map)");
  app.add_option("--tracer", c.tracer, "tracer name (tracer registry: embree, opencl:N, cuda:N)")->capture_default_str();
  app.add_option("--counts", c.counts, "light counts, comma-separated")->delimiter(',')->check(CLI::Range(1, 1 << 20))
      ->capture_default_str();
  app.add_option("--modes", c.modes, "light-sampling modes, comma-separated")->delimiter(',')
      ->check(CLI::IsMember({"tree", "all", "every"}))->capture_default_str();
  app.add_option("--width", c.width, "image width")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--height", c.height, "image height")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--spp", c.spp, "samples per pixel")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--bounces", c.bounces, "indirect bounces")->check(CLI::NonNegativeNumber)->capture_default_str();
  auto* overlap = app.add_option("--overlap", c.overlap, "lights reaching an average point (sets their radius)")
                      ->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--radius", c.radius, "fixed light radius instead of --overlap")->check(CLI::PositiveNumber)
      ->excludes(overlap);
  app.add_option("--repeats", c.repeats, "timed renders per case (the best counts)")->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--json", c.json, "JSON output")->capture_default_str();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    std::exit(app.exit(e));
  }
  return c;
}

// `count` white-ish point lights over the box, seeded by the count so every run places them alike.
std::vector<KLight> scattered_lights(int count, glm::vec3 lo, glm::vec3 hi, float radius) {
  std::mt19937 rng(uint32_t(count) * 2654435761u);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const scene::Scene no_materials;
  std::vector<KLight> lights;
  for (int i = 0; i < count; ++i) {
    scene::Light l;
    l.name = "bench_" + std::to_string(i);
    l.origin = lo + (hi - lo) * glm::vec3(u(rng), u(rng), u(rng));
    l.radius = glm::vec3(radius);
    l.color = glm::vec3(0.6f + 0.4f * u(rng), 0.6f + 0.4f * u(rng), 0.6f + 0.4f * u(rng));
    lights.push_back(core::to_klight(l, no_materials));
  }
  return lights;
}

double best_of(core::Tracer& tracer, const core::BandJob& job, int repeats) {
  core::FrameBuffer fb;
  fb.resize(int(job.camera.width), int(job.camera.height));
  tracer.render_band(job, fb);  // warm-up
  double best = 1e30;
  for (int r = 0; r < repeats; ++r) {
    const auto t = std::chrono::steady_clock::now();
    tracer.render_band(job, fb);
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count());
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  const Config cfg = parse(argc, argv);
  commit::TracerScene base;
  std::string scene_name;
  glm::vec3 start(0.0f);
  float yaw = 0.0f;
  if (core::is_scene_pack(cfg.scene)) {
    core::PackedScene pack = core::read_scene_pack(cfg.scene);
    scene_name = pack.map_name;
    start = glm::vec3(pack.player_start[0], pack.player_start[1], pack.player_start[2]);
    yaw = pack.player_yaw;
    base = std::move(pack.tracer_scene);
  } else {
    scene::Vfs vfs;
    scene::Scene map = scene::load_map(vfs, cfg.scene);
    scene_name = map.name;
    start = map.player_start;
    yaw = map.player_yaw;
    base = core::compile_scene(map).tracer_scene;
  }
  if (base.tlas_nodes.empty()) {
    std::cerr << cfg.scene << ": the scene has no geometry\n";
    return 1;
  }
  const glm::vec3 lo(base.tlas_nodes[0].bmin[0], base.tlas_nodes[0].bmin[1], base.tlas_nodes[0].bmin[2]);
  const glm::vec3 hi(base.tlas_nodes[0].bmax[0], base.tlas_nodes[0].bmax[1], base.tlas_nodes[0].bmax[2]);
  const glm::vec3 size = hi - lo;
  const double volume = double(size.x) * size.y * size.z;

  std::unique_ptr<core::Tracer> tracer = tracers::make_tracer(tracers::parse_tracer_list(cfg.tracer).front());
  core::BandJob job;
  job.camera = core::make_camera(start + glm::vec3(0.0f, 0.0f, core::kPlayerEyeHeight), {yaw, 0.0f},
                                 core::kDefaultFovX, cfg.width, cfg.height);
  job.params = core::default_frame_params();
  job.params.spp = uint32_t(cfg.spp);
  job.params.max_bounces = uint32_t(cfg.bounces);
  job.params.row_begin = 0;
  job.params.row_end = uint32_t(cfg.height);

  std::printf("scene %s (%zu triangles), %s, %dx%d, %d spp, %d bounce(s), lights %s\n", scene_name.c_str(),
              base.triangles.size(), tracer->name().c_str(), cfg.width, cfg.height, cfg.spp, cfg.bounces,
              cfg.radius > 0 ? ("of radius " + std::to_string(cfg.radius)).c_str()
                             : ("sized for " + std::to_string(cfg.overlap) + " per point").c_str());
  std::printf("%8s %10s", "lights", "radius");
  for (const std::string& m : cfg.modes) std::printf(" %12s", (m + " ms").c_str());
  std::printf("\n");
  nlohmann::json rows = nlohmann::json::array();
  for (int count : cfg.counts) {
    // A box light of half-size r covers (2r)^3: count x that = overlap x the world's volume.
    const float radius =
        cfg.radius > 0 ? cfg.radius : float(0.5 * std::cbrt(double(cfg.overlap) * volume / double(count)));
    auto scene = std::make_shared<commit::TracerScene>(base);
    scene->lights = scattered_lights(count, lo, hi, radius);
    core::rebuild_light_sampling(*scene);
    tracer->apply(commit::CommitBuffer::full(scene, uint64_t(count)));
    nlohmann::json row = {{"lights", count}, {"radius", radius}};
    std::printf("%8d %10.1f", count, radius);
    for (const std::string& mode : cfg.modes) {
      job.params.light_sampling = core::light_sampling_mode(mode);
      const double s = best_of(*tracer, job, cfg.repeats);
      row[mode + "_ms"] = s * 1e3;
      std::printf(" %12.1f", s * 1e3);
      std::fflush(stdout);
    }
    std::printf("\n");
    rows.push_back(row);
  }
  nlohmann::json report = {{"scene", scene_name}, {"tracer", tracer->name()}, {"width", cfg.width},
                           {"height", cfg.height}, {"spp", cfg.spp},          {"bounces", cfg.bounces},
                           {"overlap", cfg.overlap}, {"radius", cfg.radius}, {"rows", rows}};
  std::ofstream(cfg.json) << report.dump(2) << "\n";
  std::printf("wrote %s\n", cfg.json.c_str());
  return 0;
}
