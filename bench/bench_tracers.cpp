// Tracer throughput: paths/s and rays/s of every tracer in this build on the same frame, and for
// Embree the raw rtcIntersect1 rate on exactly the camera rays the integrator starts from, so the
// integrator's overhead is a ratio. Both tracers draw the same random numbers, so they trace the
// same rays: the Embree tracer's exact ray count stands for the others'.
//
//   bench_tracers [scene.pack | map] [--width W] [--height H] [--spp S] [--bounces B] [--repeats R] [--json FILE]
// Default: the generated test map (assets/testmap), from the player start.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cohort/core/gpu_scene.h"
#include "cohort/core/scene_pack.h"
#include "cohort/core/frame_defaults.h"
#include "cohort/core/view.h"
#include "cohort/scene/map_loader.h"
#ifdef COHORT_HAVE_EMBREE
#include "cohort/tracers/embree_tracer.h"
#endif
#ifdef COHORT_HAVE_OPENCL
#include "cohort/tracers/opencl_tracer.h"
#endif
#include "cohort/tracers/tracer_registry.h"

using namespace cohort;

namespace {

struct Config {
  std::string scene = std::string(COHORT_SOURCE_DIR) + "/assets/testmap/maps/testmap.map";
  int width = 320, height = 180, spp = 2, bounces = 1, repeats = 3;
  std::string json = "bench_tracers.json";
};

Config parse(int argc, char** argv) {
  Config c;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << a << " needs a value\n";
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--width") c.width = std::stoi(next());
    else if (a == "--height") c.height = std::stoi(next());
    else if (a == "--spp") c.spp = std::stoi(next());
    else if (a == "--bounces") c.bounces = std::stoi(next());
    else if (a == "--repeats") c.repeats = std::stoi(next());
    else if (a == "--json") c.json = next();
    else if (!a.empty() && a[0] != '-') c.scene = a;
    else {
      std::cerr << "unknown option " << a << "\n";
      std::exit(2);
    }
  }
  return c;
}

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// Best of `repeats` full-frame renders (after one warm-up), in seconds.
double time_render(core::Tracer& tracer, const core::BandJob& job, int repeats) {
  core::FrameBuffer fb;
  fb.resize(int(job.camera.width), int(job.camera.height));
  tracer.render_band(job, fb);
  double best = 1e30;
  for (int r = 0; r < repeats; ++r) {
    auto t = std::chrono::steady_clock::now();
    tracer.render_band(job, fb);
    best = std::min(best, seconds_since(t));
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  Config cfg = parse(argc, argv);
  std::shared_ptr<commit::TracerScene> scene;
  KCamera camera{};
  std::string scene_name;
  glm::vec3 start(0.0f);
  float yaw = 0.0f;
  if (core::is_scene_pack(cfg.scene)) {
    core::PackedScene pack = core::read_scene_pack(cfg.scene);
    scene_name = pack.map_name;
    start = glm::vec3(pack.player_start[0], pack.player_start[1], pack.player_start[2]);
    yaw = pack.player_yaw;
    scene = std::make_shared<commit::TracerScene>(std::move(pack.tracer_scene));
  } else {
    scene::Vfs vfs;
    scene::Scene map = scene::load_map(vfs, cfg.scene);
    scene_name = map.name;
    start = map.player_start;
    yaw = map.player_yaw;
    scene = std::make_shared<commit::TracerScene>(core::compile_scene(map).tracer_scene);
  }
  camera = core::make_camera(start + glm::vec3(0.0f, 0.0f, core::kPlayerEyeHeight), {yaw, 0.0f}, core::kDefaultFovX,
                             cfg.width, cfg.height);
  core::BandJob job;
  job.camera = camera;
  job.params = core::default_frame_params();
  job.params.spp = uint32_t(cfg.spp);
  job.params.max_bounces = uint32_t(cfg.bounces);
  job.params.light_samples = 0;  // every light reaching a point, as cohort render does by default
  job.params.row_begin = 0;
  job.params.row_end = uint32_t(cfg.height);
  const commit::CommitBuffer commit = commit::CommitBuffer::full(scene, 1);
  const double paths = double(cfg.width) * cfg.height * cfg.spp;

  nlohmann::json results = nlohmann::json::array();
  double rays_per_path = 0.0;
  std::printf("scene %s, %dx%d, %d spp, %d bounce(s), %zu triangles, %zu lights\n", scene_name.c_str(), cfg.width,
              cfg.height, cfg.spp, cfg.bounces, scene->triangles.size(), scene->lights.size());
  std::printf("%-44s %10s %12s %12s\n", "tracer", "ms/frame", "Mpaths/s", "Mrays/s");
#ifdef COHORT_HAVE_EMBREE
  {
    tracers::EmbreeTracer embree;
    embree.apply(commit);
    uint64_t before = embree.rays_traced();
    core::FrameBuffer fb;
    fb.resize(cfg.width, cfg.height);
    embree.render_band(job, fb);
    rays_per_path = double(embree.rays_traced() - before) / paths;
    double s = time_render(embree, job, cfg.repeats);
    double raw_best = 1e30;
    uint64_t hits = 0;
    for (int r = 0; r < cfg.repeats + 1; ++r) {
      auto t = std::chrono::steady_clock::now();
      hits = embree.trace_camera_rays_only(job);
      if (r > 0) raw_best = std::min(raw_best, seconds_since(t));
    }
    double mrays = paths * rays_per_path / s * 1e-6;
    double raw_mrays = paths / raw_best * 1e-6;
    std::printf("%-44s %10.1f %12.3f %12.3f\n", "embree", s * 1e3, paths / s * 1e-6, mrays);
    std::printf("%-44s %10.1f %12s %12.3f\n", "embree raw rtcIntersect1 (camera rays only)", raw_best * 1e3, "-",
                raw_mrays);
    std::printf("integrator overhead: raw camera-ray rate / integrator ray rate = %.2fx (%.2f rays per path)\n",
                raw_mrays / mrays, rays_per_path);
    results.push_back({{"tracer", "embree"}, {"ms", s * 1e3}, {"mpaths_per_s", paths / s * 1e-6},
                       {"mrays_per_s", mrays}, {"rays_per_path", rays_per_path}});
    results.push_back({{"tracer", "embree-raw-rtcIntersect1"}, {"ms", raw_best * 1e3}, {"mrays_per_s", raw_mrays},
                       {"camera_ray_hits", hits}, {"overhead_ratio", raw_mrays / mrays}});
  }
#endif
#ifdef COHORT_HAVE_OPENCL
  {
    std::vector<std::string> devices = tracers::OpenCLTracer::list_devices();
    for (size_t d = 0; d < devices.size(); ++d) {
      std::unique_ptr<core::Tracer> cl = tracers::make_tracer({"opencl", int(d), "opencl:" + std::to_string(d)});
      cl->apply(commit);
      double s = time_render(*cl, job, cfg.repeats);
      double mrays = rays_per_path > 0 ? paths * rays_per_path / s * 1e-6 : 0.0;
      std::string label = "opencl:" + std::to_string(d) + " " + devices[d];
      if (label.size() > 44) label.resize(44);
      std::printf("%-44s %10.1f %12.3f %12.3f\n", label.c_str(), s * 1e3, paths / s * 1e-6, mrays);
      results.push_back({{"tracer", "opencl:" + std::to_string(d)}, {"device", devices[d]}, {"ms", s * 1e3},
                         {"mpaths_per_s", paths / s * 1e-6}, {"mrays_per_s", mrays}});
    }
  }
#endif
  nlohmann::json report = {{"scene", scene_name}, {"width", cfg.width}, {"height", cfg.height}, {"spp", cfg.spp},
                           {"bounces", cfg.bounces}, {"results", results}};
  std::ofstream(cfg.json) << report.dump(2) << "\n";
  std::printf("wrote %s\n", cfg.json.c_str());
  return 0;
}
