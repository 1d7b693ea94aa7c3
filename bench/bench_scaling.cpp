// Scaling benchmark (issue 16, item 5): frame time and rays/s as the light count goes 8 -> 64 -> 256 ->
// 1024 and the triangle count 3k -> 300k -> 1M, on one tracer. The scenes are generated here: one room
// whose floor is a bumpy grid of the wanted triangle count, lit by a grid of point lights under the
// ceiling. Prints a table, writes JSON and a PNG chart (ms per frame against lights, a line per
// triangle count).
//   bench_scaling [--tracer embree|cuda:0|opencl:0] [options]   (bench_scaling --help lists them)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "cohort/core/frame_defaults.h"
#include "cohort/core/gpu_scene.h"
#include "cohort/core/scene_pack.h"
#include "cohort/core/view.h"
#include "cohort/tracers/tracer_registry.h"
#ifdef COHORT_HAVE_EMBREE
#include "cohort/tracers/embree_tracer.h"
#endif
#include "scaling_plot.h"

using namespace cohort;
using Clock = std::chrono::steady_clock;

namespace {

struct Config {
  std::string tracer = "embree";
  int width = 640, height = 360, spp = 1, bounces = 1, frames = 3;
  int light_samples = -1;   // -1: the renderer's default (core::default_frame_params)
  std::string light_sampling;   // empty: the renderer's default
  std::vector<int> lights = {8, 64, 256, 1024};
  std::vector<int> triangles = {3000, 300000, 1000000};
  std::string json = "out/bench_scaling.json", plot = "out/bench_scaling.png";
  std::string write_packs;  // a folder: each room also written as a scene pack, for `cohort render`
};

Config parse(int argc, char** argv) {
  Config c;
  CLI::App app{"Scaling benchmark (issue 16): frame time and rays/s as the light count and the triangle count "
               "grow, on one tracer, in generated rooms. Prints a table, writes JSON and a chart."};
  app.add_option("--tracer", c.tracer, "tracer name (tracer registry: embree, opencl:N, cuda:N)")->capture_default_str();
  app.add_option("--width", c.width, "image width")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--height", c.height, "image height")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--spp", c.spp, "samples per pixel")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--bounces", c.bounces, "indirect bounces")->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--light-sampling", c.light_sampling,
                 "how each hit picks lights, as `cohort render --light-sampling` (default: the renderer's)")
      ->check(CLI::IsMember(core::light_sampling_names()));
  app.add_option("--light-samples", c.light_samples, "lights sampled per hit (default: the renderer's)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--frames", c.frames, "timed frames per case")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--lights", c.lights, "light counts, comma-separated")->delimiter(',')->check(CLI::Range(1, 1 << 20))
      ->capture_default_str();
  app.add_option("--triangles", c.triangles, "triangle counts, comma-separated")->delimiter(',')
      ->check(CLI::Range(1, 1 << 28))->capture_default_str();
  app.add_option("--json", c.json, "JSON output")->capture_default_str();
  app.add_option("--plot", c.plot, "chart output (PNG, or PPM without OpenImageIO)")->capture_default_str();
  app.add_option("--write-packs", c.write_packs,
                 "also write each room as a scene pack (scaling_<T>t_<L>l.cpk) into this folder, so that `cohort "
                 "render` can take it (e.g. the light-sampling noise measurements of docs/integrator.md)");
  bool smoke = false;
  app.add_flag("--smoke", smoke, "tiny sizes, for the ctest that keeps the benchmark running");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    std::exit(app.exit(e));
  }
  if (smoke) {
    c.width = 64, c.height = 36, c.frames = 1;
    c.lights = {8, 64};
    c.triangles = {3000, 30000};
  }
  return c;
}

constexpr float kRoomHalf = 2048.0f, kRoomHeight = 512.0f;

void add_quad(scene::Mesh& mesh, glm::vec3 p0, glm::vec3 p1, glm::vec3 p2, glm::vec3 p3, glm::vec3 normal) {
  const uint32_t base = uint32_t(mesh.vertices.size());
  for (glm::vec3 p : {p0, p1, p2, p3}) {
    scene::Vertex v;
    v.position = p;
    v.normal = normal;
    v.st = glm::vec2(p.x, p.y) / 256.0f;
    mesh.vertices.push_back(v);
  }
  for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) mesh.indices.push_back(base + i);
}

// A closed room: a floor grid of about `triangles` triangles with bumps (so rays do not all stop in one
// node), walls and a ceiling facing inwards; `lights` point lights on a grid under the ceiling, each
// reaching a few hundred units.
scene::Scene make_room(int triangles, int lights) {
  scene::Scene s;
  s.name = "scaling_" + std::to_string(triangles) + "t_" + std::to_string(lights) + "l";
  scene::Material m;
  m.name = "grey";
  m.diffuse_color = glm::vec4(0.6f, 0.6f, 0.6f, 1.0f);
  s.materials.push_back(m);
  scene::Mesh mesh;
  mesh.name = "room";
  const int side = std::max(1, int(std::lround(std::sqrt(std::max(0, triangles - 10) / 2.0))));
  const float step = 2.0f * kRoomHalf / float(side);
  auto height = [](float x, float y) { return 24.0f * std::sin(x * 0.02f) * std::cos(y * 0.017f); };
  for (int y = 0; y <= side; ++y)
    for (int x = 0; x <= side; ++x) {
      scene::Vertex v;
      const float px = -kRoomHalf + float(x) * step, py = -kRoomHalf + float(y) * step;
      v.position = glm::vec3(px, py, height(px, py));
      v.st = glm::vec2(px, py) / 256.0f;
      mesh.vertices.push_back(v);
    }
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x) {
      const uint32_t a = uint32_t(y * (side + 1) + x), b = a + 1, c = a + uint32_t(side + 1), d = c + 1;
      for (uint32_t i : {a, b, d, a, d, c}) mesh.indices.push_back(i);
    }
  const float h = kRoomHalf, top = kRoomHeight, low = -64.0f;
  add_quad(mesh, {-h, -h, top}, {-h, h, top}, {h, h, top}, {h, -h, top}, {0, 0, -1});
  add_quad(mesh, {-h, -h, low}, {h, -h, low}, {h, -h, top}, {-h, -h, top}, {0, 1, 0});
  add_quad(mesh, {h, h, low}, {-h, h, low}, {-h, h, top}, {h, h, top}, {0, -1, 0});
  add_quad(mesh, {-h, h, low}, {-h, -h, low}, {-h, -h, top}, {-h, h, top}, {1, 0, 0});
  add_quad(mesh, {h, -h, low}, {h, h, low}, {h, h, top}, {h, -h, top}, {-1, 0, 0});
  mesh.surfaces.push_back({0, 0, uint32_t(mesh.indices.size())});
  s.meshes.push_back(std::move(mesh));
  s.area_meshes.push_back(0);

  const int per_row = int(std::ceil(std::sqrt(double(lights))));
  for (int i = 0; i < lights; ++i) {
    scene::Light l;
    l.name = "light_" + std::to_string(i);
    const float fx = (float(i % per_row) + 0.5f) / float(per_row), fy = (float(i / per_row) + 0.5f) / float(per_row);
    l.origin = glm::vec3(-h + 2.0f * h * fx, -h + 2.0f * h * fy, top - 64.0f);
    l.radius = glm::vec3(std::max(600.0f, 2.5f * 2.0f * h / float(per_row)));
    l.color = glm::vec3(1.0f, 0.9f, 0.8f) * (8.0f / float(std::min(lights, 64)));
    s.lights.push_back(l);
  }
  s.player_start = glm::vec3(-h + 200.0f, -h + 200.0f, 200.0f);
  s.player_yaw = 45.0f;
  return s;
}

struct Result {
  int triangles = 0, lights = 0;
  size_t scene_triangles = 0;
  double compile_ms = 0, apply_ms = 0, frame_ms = 0, mrays_per_s = 0, mpaths_per_s = 0;
};

// Rays traced so far, for tracers that count them outside their per-row work (Embree); else 0.
uint64_t rays_counted(const core::Tracer& tracer) {
#ifdef COHORT_HAVE_EMBREE
  if (const auto* embree = dynamic_cast<const tracers::EmbreeTracer*>(&tracer)) return embree->rays_traced();
#endif
  (void)tracer;
  return 0;
}

double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

Result run_one(const Config& cfg, int triangles, int lights) {
  Result r;
  r.triangles = triangles;
  r.lights = lights;
  scene::Scene room = make_room(triangles, lights);
  const glm::vec3 eye = room.player_start;
  const float yaw = room.player_yaw;
  const std::string name = room.name;
  auto t0 = Clock::now();
  core::CompiledScene compiled = core::compile_scene(std::move(room));
  r.compile_ms = ms_since(t0);
  if (!cfg.write_packs.empty()) {
    core::PackedScene pack;
    pack.map_name = name;
    pack.tracer_scene = compiled.tracer_scene;
    pack.blas_of_mesh = compiled.blas_of_mesh;
    pack.world_blas = compiled.world_blas;
    pack.instance_names.assign(pack.tracer_scene.instances.size(), "world");
    for (int k = 0; k < 3; ++k) pack.player_start[k] = eye[k];
    pack.player_yaw = yaw;
    std::filesystem::create_directories(cfg.write_packs);
    core::write_scene_pack(std::filesystem::path(cfg.write_packs) / (name + ".cpk"), pack);
  }
  auto scene = std::make_shared<commit::TracerScene>(std::move(compiled.tracer_scene));
  r.scene_triangles = scene->triangles.size();
  std::unique_ptr<core::Tracer> tracer = tracers::make_tracer(tracers::parse_tracer_list(cfg.tracer).at(0));
  t0 = Clock::now();
  tracer->apply(commit::CommitBuffer::full(scene, 1));
  r.apply_ms = ms_since(t0);

  core::BandJob job;
  job.camera = core::make_camera(eye, {yaw, -12.0f}, core::kDefaultFovX, cfg.width, cfg.height);
  job.params = core::default_frame_params();
  job.params.spp = uint32_t(cfg.spp);
  job.params.max_bounces = uint32_t(cfg.bounces);
  if (cfg.light_samples >= 0) job.params.light_samples = uint32_t(cfg.light_samples);
  if (!cfg.light_sampling.empty()) job.params.light_sampling = core::light_sampling_mode(cfg.light_sampling);
  job.params.row_begin = 0;
  job.params.row_end = uint32_t(cfg.height);
  core::FrameBuffer fb;
  fb.resize(cfg.width, cfg.height);
  tracer->render_band(job, fb);   // warm-up: first-use allocations, kernel compilation
  double best = 1e30, rays = 0;
  for (int f = 0; f < cfg.frames; ++f) {
    job.params.frame_index = uint32_t(f + 1);
    t0 = Clock::now();
    const uint64_t counted_before = rays_counted(*tracer);
    core::BandResult band = tracer->render_band(job, fb);
    const double ms = ms_since(t0);
    if (ms < best) {
      best = ms;
      rays = band.row_work.empty() ? double(rays_counted(*tracer) - counted_before)
                                   : std::accumulate(band.row_work.begin(), band.row_work.end(), 0.0);
    }
  }
  r.frame_ms = best;
  r.mpaths_per_s = double(cfg.width) * cfg.height * cfg.spp / (best * 1e3);
  r.mrays_per_s = rays / (best * 1e3);   // 0 when the tracer counts no rays
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  const Config cfg = parse(argc, argv);
  try {
    if (tracers::parse_tracer_list(cfg.tracer).size() != 1) throw std::runtime_error("name exactly one tracer");
    tracers::make_tracer(tracers::parse_tracer_list(cfg.tracer).at(0));
  } catch (const std::exception& e) {
    std::cerr << "bench_scaling: tracer '" << cfg.tracer << "': " << e.what() << "\n";
    return 3;
  }
  const KFrameParams defaults = core::default_frame_params();
  const int light_samples = cfg.light_samples >= 0 ? cfg.light_samples : int(defaults.light_samples);
  const std::string light_sampling =
      cfg.light_sampling.empty() ? core::light_sampling_names().at(defaults.light_sampling) : cfg.light_sampling;
  std::printf("bench_scaling: tracer %s, %dx%d, %d spp, %d bounce(s), light sampling %s, light samples %d%s, best of "
              "%d frames\n",
              cfg.tracer.c_str(), cfg.width, cfg.height, cfg.spp, cfg.bounces, light_sampling.c_str(), light_samples,
              light_samples == 0 ? " (every light)" : "", cfg.frames);
  std::printf("%10s %7s %11s %10s %10s %10s %10s %10s\n", "triangles", "lights", "scene tris", "compile ms",
              "apply ms", "ms/frame", "Mpaths/s", "Mrays/s");
  std::vector<Result> results;
  for (int t : cfg.triangles)
    for (int l : cfg.lights) {
      Result r = run_one(cfg, t, l);
      std::printf("%10d %7d %11zu %10.0f %10.0f %10.2f %10.3f %10.3f\n", r.triangles, r.lights, r.scene_triangles,
                  r.compile_ms, r.apply_ms, r.frame_ms, r.mpaths_per_s, r.mrays_per_s);
      std::fflush(stdout);
      results.push_back(r);
    }

  nlohmann::json report = {{"tracer", cfg.tracer}, {"width", cfg.width}, {"height", cfg.height}, {"spp", cfg.spp},
                           {"bounces", cfg.bounces}, {"light_samples", light_samples},
                           {"light_sampling", light_sampling}, {"frames", cfg.frames}};
  std::vector<bench::ScalingSeries> series;
  for (int t : cfg.triangles) {
    bench::ScalingSeries s;
    s.label = std::to_string(t) + " triangles";
    for (const Result& r : results)
      if (r.triangles == t) s.points.push_back({double(r.lights), r.frame_ms});
    series.push_back(s);
  }
  for (const Result& r : results)
    report["results"].push_back({{"triangles", r.triangles}, {"scene_triangles", r.scene_triangles},
                                 {"lights", r.lights}, {"compile_ms", r.compile_ms}, {"apply_ms", r.apply_ms},
                                 {"frame_ms", r.frame_ms}, {"mpaths_per_s", r.mpaths_per_s},
                                 {"mrays_per_s", r.mrays_per_s}});
  for (const std::string& file : {cfg.json, cfg.plot}) {
    const std::filesystem::path p(file);
    if (p.has_parent_path()) std::filesystem::create_directories(p.parent_path());
  }
  std::ofstream(cfg.json) << report.dump(2) << "\n";
  bench::write_scaling_plot(cfg.plot, "ms per frame, " + cfg.tracer + ", " + std::to_string(cfg.width) + "x" +
                                          std::to_string(cfg.height) + " " + std::to_string(cfg.spp) + " spp",
                            "lights", "ms/frame", series);
  std::printf("wrote %s and %s\n", cfg.json.c_str(), cfg.plot.c_str());
  return 0;
}
