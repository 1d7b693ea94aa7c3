// CUDA tracer benchmark on a scene pack: Mrays/s for primary, shadow and bounce rays, and ms per
// 1920x1080 frame at 1 spp with next-event estimation and one bounce, on 1, 2, 4... GPUs with the
// scaling ratio. Prints a table and writes JSON.
//   bench_cuda --scene FILE.cpk [--width 1920] [--height 1080] [--frames 20] [--json PATH]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "cohort/balance/order_statistics.h"
#include "cohort/core/gpu_scene.h"
#include "cohort/core/scene_pack.h"
#include "cohort/core/frame_defaults.h"
#include "cohort/core/view.h"
#ifdef COHORT_HAVE_CUDA
#include "cohort/tracers/cuda_tracer.h"
#endif

using namespace cohort;
using Clock = std::chrono::steady_clock;

#ifdef COHORT_HAVE_CUDA
namespace {

KFrameParams bench_params(uint32_t mode, uint32_t bounces, int height) {
  KFrameParams p = core::default_frame_params();
  p.max_bounces = bounces;
  p.mode = mode;
  p.row_end = uint32_t(height);
  return p;
}

}  // namespace
#endif

int main(int argc, char** argv) {
  std::string scene_file, json_path = "out/bench_cuda.json";
  int width = 1920, height = 1080, frames = 20;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) throw std::invalid_argument(a + " needs a value");
      return argv[++i];
    };
    if (a == "--scene") scene_file = next();
    else if (a == "--width") width = std::stoi(next());
    else if (a == "--height") height = std::stoi(next());
    else if (a == "--frames") frames = std::stoi(next());
    else if (a == "--json") json_path = next();
    else {
      std::fprintf(stderr, "usage: bench_cuda --scene FILE.cpk [--width W] [--height H] [--frames N] [--json PATH]\n");
      return 2;
    }
  }
#ifndef COHORT_HAVE_CUDA
  std::fprintf(stderr, "bench_cuda: this build has no CUDA tracer\n");
  return 3;
#else
  if (scene_file.empty()) {
    std::fprintf(stderr, "bench_cuda: --scene FILE.cpk is required (make one with `cohort pack`)\n");
    return 2;
  }
  const int gpus = tracers::cuda_device_count();
  if (gpus == 0) {
    std::fprintf(stderr, "bench_cuda: no CUDA device on this machine\n");
    return 3;
  }
  core::PackedScene pack = core::read_scene_pack(scene_file);
  auto scene = std::make_shared<commit::TracerScene>(pack.tracer_scene);
  glm::vec3 eye(pack.player_start[0], pack.player_start[1], pack.player_start[2] + core::kPlayerEyeHeight);
  KCamera cam = core::make_camera(eye, {pack.player_yaw, 0.0f}, core::kDefaultFovX, width, height);
  nlohmann::json out;
  out["scene"] = pack.map_name;
  out["width"] = width;
  out["height"] = height;
  out["gpu"] = tracers::cuda_device_name(0);
  out["gpus"] = gpus;
  const double pixels = double(width) * height;

  std::vector<std::unique_ptr<tracers::CudaTracer>> tracers_;
  for (int g = 0; g < gpus; ++g) {
    tracers_.push_back(std::make_unique<tracers::CudaTracer>(g));
    tracers_.back()->apply(commit::CommitBuffer::full(scene, 1));
  }
  core::FrameBuffer frame;
  frame.resize(width, height);

  std::printf("%s, %s, %dx%d, 1 spp, %d frames per case\n", pack.map_name.c_str(), tracers::cuda_device_name(0).c_str(),
              width, height, frames);
  std::printf("\nRay throughput on one GPU (kernel time, CUDA events)\n");
  std::printf("%-34s %10s %14s %14s %10s\n", "case", "kernel ms", "closest rays", "shadow rays", "Mrays/s");
  struct Mode {
    const char* name;
    uint32_t mode, bounces;
  };
  double primary_ms = 0, direct_ms = 0, path_ms = 0;
  unsigned long long direct_shadow = 0, path_closest = 0, path_shadow = 0;
  for (Mode m : {Mode{"primary (albedo view)", K_MODE_ALBEDO, 0}, Mode{"primary + shadow (direct)", K_MODE_DIRECT, 0},
                 Mode{"path: NEE + 1 bounce", K_MODE_PATH, 1}}) {
    auto& t = *tracers_[0];
    core::BandJob job;
    job.params = bench_params(m.mode, m.bounces, height);
    job.camera = cam;
    std::vector<double> ms;
    for (int f = 0; f < frames + 3; ++f) {
      job.params.frame_index = uint32_t(f);
      double k = t.render_band(job, frame).device_ms;
      if (f >= 3) ms.push_back(k);
    }
    t.set_ray_counting(true);
    t.render_band(job, frame);
    auto counts = t.last_ray_counts();
    t.set_ray_counting(false);
    double kernel = median(ms);
    double mrays = double(counts.closest + counts.occlusion) / (kernel * 1e3);
    std::printf("%-34s %10.3f %14llu %14llu %10.1f\n", m.name, kernel, counts.closest, counts.occlusion, mrays);
    out["modes"].push_back({{"case", m.name}, {"kernel_ms", kernel}, {"closest_rays", counts.closest},
                            {"shadow_rays", counts.occlusion}, {"mrays_per_s", mrays}});
    if (m.mode == K_MODE_ALBEDO) primary_ms = kernel;
    if (m.mode == K_MODE_DIRECT) direct_ms = kernel, direct_shadow = counts.occlusion;
    if (m.mode == K_MODE_PATH) path_ms = kernel, path_closest = counts.closest, path_shadow = counts.occlusion;
  }
  // Per ray type: primary rays alone; shadow rays from the time the direct view adds; bounce rays
  // (closest hits beyond the primary ones, with their shadow rays) from the time the path adds.
  double primary_rate = pixels / (primary_ms * 1e3);
  double shadow_rate = direct_ms > primary_ms ? double(direct_shadow) / ((direct_ms - primary_ms) * 1e3) : 0.0;
  double bounce_rays = double(path_closest) - pixels + double(path_shadow) - double(direct_shadow);
  double bounce_rate = path_ms > direct_ms ? bounce_rays / ((path_ms - direct_ms) * 1e3) : 0.0;
  std::printf("\n%-34s %10.1f\n%-34s %10.1f\n%-34s %10.1f\n", "primary Mrays/s", primary_rate,
              "shadow Mrays/s (incremental)", shadow_rate, "bounce + its shadow Mrays/s (incr.)", bounce_rate);
  out["mrays_per_s"] = {{"primary", primary_rate}, {"shadow", shadow_rate}, {"bounce", bounce_rate}};

  std::printf("\nFrame time, path tracing 1 spp NEE + 1 bounce, bands split evenly (4-row units)\n");
  std::printf("%-6s %14s %14s %14s %10s\n", "GPUs", "frame ms", "max kernel ms", "frames/s", "scaling");
  double one_gpu_ms = 0.0;
  for (int n = 1; n <= gpus; n = n < gpus && n * 2 > gpus ? gpus : n * 2) {
    std::vector<double> frame_ms, kernel_ms;
    const int units = (height + 3) / 4;
    for (int f = 0; f < frames + 3; ++f) {
      std::vector<double> k(size_t(n), 0.0);
      auto t0 = Clock::now();
      std::vector<std::thread> threads;
      for (int g = 0; g < n; ++g)
        threads.emplace_back([&, g] {
          core::BandJob job;
          job.params = bench_params(K_MODE_PATH, 1, height);
          job.params.frame_index = uint32_t(f);
          job.params.row_begin = uint32_t(std::min(height, units * g / n * 4));
          job.params.row_end = uint32_t(g == n - 1 ? height : std::min(height, units * (g + 1) / n * 4));
          job.camera = cam;
          k[size_t(g)] = tracers_[size_t(g)]->render_band(job, frame).device_ms;
        });
      for (auto& th : threads) th.join();
      double wall = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
      if (f >= 3) frame_ms.push_back(wall), kernel_ms.push_back(*std::max_element(k.begin(), k.end()));
    }
    double ms = median(frame_ms);
    if (n == 1) one_gpu_ms = ms;
    double scaling = one_gpu_ms / ms;
    std::printf("%-6d %14.2f %14.2f %14.1f %9.2fx\n", n, ms, median(kernel_ms), 1000.0 / ms, scaling);
    out["frames"].push_back({{"gpus", n}, {"frame_ms", ms}, {"max_kernel_ms", median(kernel_ms)}, {"scaling", scaling}});
    if (n == gpus) break;
  }
  std::filesystem::path jp(json_path);
  if (jp.has_parent_path()) std::filesystem::create_directories(jp.parent_path());
  std::ofstream(jp) << out.dump(2) << "\n";
  std::printf("\nJSON: %s\n", json_path.c_str());
  return 0;
#endif
}
