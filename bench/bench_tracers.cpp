// The Embree tracer's integrator overhead per ray class: the integrator's rays/s against raw Embree
// rays/s on exactly the rays the integrator traces. The tracer records every ray of a frame by class
// (camera, shadow, diffuse bounce); the same rays are then traced with nothing around them through
// rtcIntersect1/rtcOccluded1, 8-ray packets and 256-ray streams, with the integrator's filter functions.
//
// The integrator's time per class is its marginal cost, from three renders of the same frame that stop
// earlier or later (the random numbers, hence the rays, are the same in all three):
//   camera  = albedo mode (camera rays and their surfaces)                        rays: the camera rays
//   shadow  = direct mode - albedo mode (light picking, BRDFs, first-hit shadows)  rays: those shadow rays
//   bounce  = path mode - direct mode (bounce rays, their surfaces and shadows)    rays: bounce + their shadows
// Times are process CPU time (best of --repeats), so rates are per core and hold up on a loaded machine;
// --threads 1 (the default) keeps every ray on one core.
//
//   bench_tracers [scene.pack | map] [--large MAP|none] [--width W] [--height H] [--spp S]
//                 [--light-samples L] [--light-sampling MODE] [--camera X Y Z YAW PITCH] [--bounces B]
//                 [--threads T] [--repeats R] [--json FILE] [--others] [--frame-only]
// Default: the generated test map (assets/testmap) from the player start, then the large map
// (tools/gen_testmap.py --large) when it has been generated into the build folder.
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "cohort/core/frame_defaults.h"
#include "cohort/core/gpu_scene.h"
#include "cohort/core/scene_pack.h"
#include "cohort/core/view.h"
#include "cohort/scene/map_loader.h"
#ifdef COHORT_HAVE_EMBREE
#include "cohort/tracers/embree_tracer.h"
#endif
#include "cohort/tracers/tracer_registry.h"

using namespace cohort;

namespace {

struct Config {
  std::string scene = std::string(COHORT_SOURCE_DIR) + "/assets/testmap/maps/testmap.map";
  std::string large = std::string(COHORT_SOURCE_DIR) + "/build/default/assets/largemap/maps/largemap.map";
  int width = 640, height = 360, spp = 1, light_samples = 1, bounces = 1, threads = 1, repeats = 3;
  std::string light_sampling = core::light_sampling_name(core::default_frame_params().light_sampling);
  std::vector<float> camera;   // x y z yaw pitch for every scene; empty: each scene's player start
  std::string json;
  bool others = false;
  bool frame_only = false;
};

Config parse(int argc, char** argv) {
  Config c;
  CLI::App app{"Integrator overhead of the Embree tracer per ray class (camera, shadow, diffuse bounce): the "
               "integrator's rays/s against raw Embree rays/s on the same rays. Prints a table per scene."};
  app.add_option("scene", c.scene, "scene pack or .map (default: the generated test map)");
  app.add_option("--large", c.large, "second scene, measured when the file exists ('none' skips it)")
      ->capture_default_str();
  app.add_option("--width", c.width, "image width")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--height", c.height, "image height")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--spp", c.spp, "samples per pixel")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--light-samples", c.light_samples, "light samples per vertex (0: every light)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--light-sampling", c.light_sampling, "how each hit picks lights (cohort render --light-sampling)")
      ->check(CLI::IsMember(core::light_sampling_names()))
      ->capture_default_str();
  app.add_option("--camera", c.camera, "x y z yaw pitch (Doom 3 angles, degrees) for every scene, instead of its "
                 "player start at eye height")
      ->expected(5);
  app.add_option("--bounces", c.bounces, "indirect bounces")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--threads", c.threads, "threads (0: all cores)")->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--repeats", c.repeats, "timed runs per measurement (the best counts)")
      ->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--json", c.json, "also write the results as JSON to this file");
  app.add_flag("--others", c.others, "also time whole frames on every other tracer this build has");
  app.add_flag("--frame-only", c.frame_only,
               "only the whole path-mode frame's best CPU time per scene (no ray classes, no raw rays): a quick "
               "before/after comparison");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    std::exit(app.exit(e));
  }
  return c;
}

double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

// Best CPU time of `repeats` runs of f, after one untimed warm-up run.
double best_cpu_seconds(int repeats, const std::function<void()>& f) {
  f();
  double best = 1e30;
  for (int r = 0; r < repeats; ++r) {
    const double t = cpu_seconds();
    f();
    best = std::min(best, cpu_seconds() - t);
  }
  return best;
}

struct LoadedScene {
  std::string name;
  std::shared_ptr<commit::TracerScene> scene;
  KCamera camera{};
};

LoadedScene load(const std::string& path, int width, int height, const std::vector<float>& camera) {
  LoadedScene s;
  glm::vec3 start(0.0f);
  float yaw = 0.0f;
  if (core::is_scene_pack(path)) {
    core::PackedScene pack = core::read_scene_pack(path);
    s.name = pack.map_name;
    start = glm::vec3(pack.player_start[0], pack.player_start[1], pack.player_start[2]);
    yaw = pack.player_yaw;
    s.scene = std::make_shared<commit::TracerScene>(std::move(pack.tracer_scene));
  } else {
    scene::Vfs vfs;
    scene::Scene map = scene::load_map(vfs, path);
    s.name = map.name;
    start = map.player_start;
    yaw = map.player_yaw;
    s.scene = std::make_shared<commit::TracerScene>(core::compile_scene(map).tracer_scene);
  }
  if (camera.size() == 5)
    s.camera = core::make_camera({camera[0], camera[1], camera[2]}, {camera[3], camera[4]}, core::kDefaultFovX, width,
                                 height);
  else
    s.camera = core::make_camera(start + glm::vec3(0.0f, 0.0f, core::kPlayerEyeHeight), {yaw, 0.0f},
                                 core::kDefaultFovX, width, height);
  return s;
}

core::BandJob make_job(const Config& cfg, const KCamera& camera, kuint mode) {
  core::BandJob job;
  job.camera = camera;
  job.params = core::default_frame_params();
  job.params.spp = uint32_t(cfg.spp);
  job.params.max_bounces = uint32_t(cfg.bounces);
  job.params.light_samples = uint32_t(cfg.light_samples);
  job.params.light_sampling = core::light_sampling_mode(cfg.light_sampling);
  job.params.mode = mode;
  job.params.row_begin = 0;
  job.params.row_end = uint32_t(cfg.height);
  return job;
}

#ifdef COHORT_HAVE_EMBREE
// Raw CPU seconds of one ray set per Embree API (single, packet8, stream).
struct RawTimes {
  double api[3] = {0.0, 0.0, 0.0};
  double best() const { return std::min(api[0], std::min(api[1], api[2])); }
};

const char* kApiNames[3] = {"rtcIntersect1/rtcOccluded1", "8-ray packets", "1M streams of 256"};

RawTimes time_raw(tracers::EmbreeTracer& embree, const std::vector<tracers::EmbreeRay>& rays, bool occlusion,
                  bool coherent, int repeats) {
  const tracers::EmbreeRayApi apis[3] = {tracers::EmbreeRayApi::single, tracers::EmbreeRayApi::packet8,
                                         tracers::EmbreeRayApi::stream};
  RawTimes t;
  for (int a = 0; a < 3; ++a)
    t.api[a] = best_cpu_seconds(repeats, [&] { embree.trace_raw(rays, occlusion, apis[a], coherent); });
  return t;
}

struct ClassRow {
  std::string name;
  double rays = 0.0;
  double integrator_s = 0.0;
  RawTimes raw;
};

nlohmann::json measure_embree_frame(const Config& cfg, const LoadedScene& s) {
  tracers::EmbreeTracer embree(cfg.threads);
  embree.apply(commit::CommitBuffer::full(s.scene, 1));
  const core::BandJob path = make_job(cfg, s.camera, K_MODE_PATH);
  core::FrameBuffer fb;
  fb.resize(cfg.width, cfg.height);
  const double t_path = best_cpu_seconds(cfg.repeats, [&] { embree.render_band(path, fb); });
  std::printf("\nscene %s: %dx%d, %d spp, %d light sample(s), %d bounce(s), %s\n", s.name.c_str(), cfg.width,
              cfg.height, cfg.spp, cfg.light_samples, cfg.bounces,
              cfg.threads == 1 ? "1 thread" : (std::to_string(cfg.threads) + " threads (0: all)").c_str());
  std::printf("whole frame: %.1f ms CPU (best of %d)\n", t_path * 1e3, cfg.repeats);
  return {{"scene", s.name}, {"frame_cpu_ms", t_path * 1e3}};
}

nlohmann::json measure_embree(const Config& cfg, const LoadedScene& s) {
  if (cfg.frame_only) return measure_embree_frame(cfg, s);
  tracers::EmbreeTracer embree(cfg.threads);
  embree.apply(commit::CommitBuffer::full(s.scene, 1));
  const core::BandJob albedo = make_job(cfg, s.camera, K_MODE_ALBEDO);
  const core::BandJob direct = make_job(cfg, s.camera, K_MODE_DIRECT);
  const core::BandJob path = make_job(cfg, s.camera, K_MODE_PATH);

  const tracers::EmbreeRaySet camera_set = embree.record_rays(albedo);
  const tracers::EmbreeRaySet direct_set = embree.record_rays(direct);
  const tracers::EmbreeRaySet path_set = embree.record_rays(path);

  core::FrameBuffer fb;
  fb.resize(cfg.width, cfg.height);
  auto render = [&](const core::BandJob& job) {
    return best_cpu_seconds(cfg.repeats, [&] { embree.render_band(job, fb); });
  };
  const double t_albedo = render(albedo), t_direct = render(direct), t_path = render(path);

  const int r = cfg.repeats;
  const RawTimes raw_camera = time_raw(embree, camera_set.camera, false, true, r);
  const RawTimes raw_first_shadow = time_raw(embree, direct_set.shadow, true, false, r);
  const RawTimes raw_all_shadow = time_raw(embree, path_set.shadow, true, false, r);
  const RawTimes raw_bounce = time_raw(embree, path_set.bounce, false, false, r);

  std::vector<ClassRow> rows(4);
  rows[0] = {"camera", double(camera_set.camera.size()), t_albedo, raw_camera};
  rows[1] = {"shadow (first hit)", double(direct_set.shadow.size()), t_direct - t_albedo, raw_first_shadow};
  rows[2].name = "diffuse bounce (+ its shadows)";
  rows[2].rays = double(path_set.bounce.size() + path_set.shadow.size() - direct_set.shadow.size());
  rows[2].integrator_s = t_path - t_direct;
  rows[3].name = "whole frame";
  rows[3].rays = double(path_set.camera.size() + path_set.shadow.size() + path_set.bounce.size());
  rows[3].integrator_s = t_path;
  for (int a = 0; a < 3; ++a) {
    rows[2].raw.api[a] = raw_bounce.api[a] + raw_all_shadow.api[a] - raw_first_shadow.api[a];
    rows[3].raw.api[a] = raw_camera.api[a] + raw_all_shadow.api[a] + raw_bounce.api[a];
  }

  const double paths = double(cfg.width) * cfg.height * cfg.spp;
  std::printf("\nscene %s: %dx%d, %d spp, %d light sample(s), %d bounce(s), %zu triangles, %zu lights, %s\n",
              s.name.c_str(), cfg.width, cfg.height, cfg.spp, cfg.light_samples, cfg.bounces,
              s.scene->triangles.size(), s.scene->lights.size(),
              cfg.threads == 1 ? "1 thread" : (std::to_string(cfg.threads) + " threads (0: all)").c_str());
  std::printf("whole frame: %.1f ms CPU, %.3f Mpaths/s per core, %.2f rays per path\n", t_path * 1e3,
              paths / t_path * 1e-6, rows[3].rays / paths);
  // Direct mode's shadow rays stand for the camera hits' (its emissive samples skip the bounce's MIS weight,
  // so a few roulette choices differ from path mode's).
  std::printf("shadow rays per path (%s): %.3f at the camera ray's hit, %.3f after bounces\n",
              cfg.light_sampling.c_str(), double(direct_set.shadow.size()) / paths,
              (double(path_set.shadow.size()) - double(direct_set.shadow.size())) / paths);
  std::printf("Mrays/s per core; overhead = fastest raw rate / integrator rate (goal <= 1.3)\n");
  std::printf("%-31s %10s %11s %11s %11s %11s %9s\n", "ray class", "rays", "integrator", "raw 1",
              "raw 8", "raw 1M", "overhead");
  nlohmann::json classes = nlohmann::json::array();
  for (const ClassRow& row : rows) {
    auto rate = [&](double s) { return s > 0.0 ? row.rays / s * 1e-6 : 0.0; };
    const double overhead = row.integrator_s > 0.0 ? row.integrator_s / row.raw.best() : 0.0;
    std::printf("%-31s %10.0f %11.3f %11.3f %11.3f %11.3f %8.2fx\n", row.name.c_str(), row.rays,
                rate(row.integrator_s), rate(row.raw.api[0]), rate(row.raw.api[1]), rate(row.raw.api[2]), overhead);
    nlohmann::json raw = nlohmann::json::object();
    for (int a = 0; a < 3; ++a) raw[kApiNames[a]] = rate(row.raw.api[a]);
    classes.push_back({{"class", row.name}, {"rays", row.rays}, {"integrator_mrays_per_s", rate(row.integrator_s)},
                       {"raw_mrays_per_s", raw}, {"overhead", overhead}});
  }
  return {{"scene", s.name}, {"triangles", s.scene->triangles.size()}, {"lights", s.scene->lights.size()},
          {"frame_cpu_ms", t_path * 1e3}, {"rays_per_path", rows[3].rays / paths},
          {"shadow_rays_per_path", double(path_set.shadow.size()) / paths},
          {"first_hit_shadow_rays_per_path", double(direct_set.shadow.size()) / paths}, {"classes", classes}};
}
#endif

// Whole-frame wall time of every other tracer the build has, on the path-mode frame.
nlohmann::json measure_others(const Config& cfg, const LoadedScene& s) {
  nlohmann::json results = nlohmann::json::array();
  const core::BandJob job = make_job(cfg, s.camera, K_MODE_PATH);
  for (const std::string& kind : tracers::built_tracer_kinds()) {
    if (kind == "embree") continue;
    for (int d = 0; d < tracers::device_count(kind); ++d) {
      const std::string name = kind + ":" + std::to_string(d);
      std::unique_ptr<core::Tracer> tracer = tracers::make_tracer(tracers::parse_tracer_list(name).front());
      tracer->apply(commit::CommitBuffer::full(s.scene, 1));
      core::FrameBuffer fb;
      fb.resize(cfg.width, cfg.height);
      tracer->render_band(job, fb);
      double best = 1e30;
      for (int r = 0; r < cfg.repeats; ++r) {
        auto t = std::chrono::steady_clock::now();
        tracer->render_band(job, fb);
        best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count());
      }
      std::printf("%-31s %10.1f ms/frame (wall)\n", name.c_str(), best * 1e3);
      results.push_back({{"tracer", name}, {"wall_ms", best * 1e3}});
    }
  }
  return results;
}

}  // namespace

static int run(const Config& cfg) {
  std::vector<std::string> scenes = {cfg.scene};
  if (cfg.large != "none") {
    if (std::filesystem::exists(cfg.large))
      scenes.push_back(cfg.large);
    else
      std::printf("no large map at %s (python3 tools/gen_testmap.py --large --out build/default/assets/largemap)\n",
                  cfg.large.c_str());
  }
  nlohmann::json report = {{"width", cfg.width}, {"height", cfg.height}, {"spp", cfg.spp},
                           {"light_samples", cfg.light_samples}, {"light_sampling", cfg.light_sampling},
                           {"bounces", cfg.bounces},
                           {"threads", cfg.threads}, {"scenes", nlohmann::json::array()}};
  for (const std::string& path : scenes) {
    const LoadedScene s = load(path, cfg.width, cfg.height, cfg.camera);
    nlohmann::json entry = {{"scene", s.name}};
#ifdef COHORT_HAVE_EMBREE
    entry["embree"] = measure_embree(cfg, s);
#else
    std::printf("this build has no Embree tracer: nothing to compare\n");
#endif
    if (cfg.others) entry["others"] = measure_others(cfg, s);
    report["scenes"].push_back(entry);
  }
  if (!cfg.json.empty()) {
    std::ofstream(cfg.json) << report.dump(2) << "\n";
    std::printf("wrote %s\n", cfg.json.c_str());
  }
  return 0;
}

int main(int argc, char** argv) {
  const Config cfg = parse(argc, argv);
  try {
    return run(cfg);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_tracers: %s\n", e.what());
    return 1;
  }
}
