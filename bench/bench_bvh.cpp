// BVH benchmark: BLAS build throughput (1 thread and all), refit time, TLAS build time over 100/1,000/
// 10,000 instances, SAH cost. Prints a table and writes JSON.
//   bench_bvh [--triangles N] [--json PATH]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "cohort/core/bvh.h"

using namespace cohort::core;
using Clock = std::chrono::steady_clock;

namespace {

// A bumpy terrain grid: realistic, spatially coherent triangles (unlike a random soup).
void make_terrain(int side, std::vector<KVertex>& vertices, std::vector<KTriangle>& triangles) {
  vertices.resize(size_t(side + 1) * (side + 1));
  for (int y = 0; y <= side; ++y)
    for (int x = 0; x <= side; ++x) {
      KVertex& v = vertices[size_t(y) * (side + 1) + x];
      v = KVertex{};
      v.pos[0] = float(x);
      v.pos[1] = float(y);
      v.pos[2] = 8.0f * std::sin(x * 0.05f) * std::cos(y * 0.07f);
    }
  triangles.clear();
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x) {
      uint32_t a = uint32_t(y * (side + 1) + x), b = a + 1, c = a + uint32_t(side + 1), d = c + 1;
      triangles.push_back({a, c, b, 0});
      triangles.push_back({b, c, d, 0});
    }
}

template <class F> double best_ms(int repeats, F&& f) {
  double best = 1e30;
  for (int i = 0; i < repeats; ++i) {
    auto t0 = Clock::now();
    f();
    best = std::min(best, std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  int triangles_wanted = 1000000;
  std::string json_path = "out/bench_bvh.json";
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--triangles" && i + 1 < argc) triangles_wanted = std::stoi(argv[++i]);
    else if (a == "--json" && i + 1 < argc) json_path = argv[++i];
    else {
      std::fprintf(stderr, "usage: bench_bvh [--triangles N] [--json PATH]\n");
      return 2;
    }
  }
  const int side = int(std::sqrt(triangles_wanted / 2.0));
  std::vector<KVertex> vertices;
  std::vector<KTriangle> triangles;
  make_terrain(side, vertices, triangles);
  const unsigned hw = std::max(1u, std::thread::hardware_concurrency());
  nlohmann::json out;
  out["machine_threads"] = hw;
  out["triangles"] = triangles.size();

  std::printf("BLAS build over %zu triangles (terrain), %u hardware threads\n", triangles.size(), hw);
  std::printf("%-22s %12s %12s %10s\n", "case", "ms", "Mtris/s", "SAH");
  BlasBuild built;
  for (int threads : {1, int(hw)}) {
    BvhBuildOptions options;
    options.threads = threads;
    double ms = best_ms(3, [&] { built = build_blas(vertices, triangles, options); });
    double mtris = triangles.size() / (ms * 1e3);
    std::printf("%-22s %12.1f %12.2f %10.2f\n", ("build, " + std::to_string(threads) + " thread(s)").c_str(), ms, mtris,
                built.sah_cost);
    out["blas_build"].push_back({{"threads", threads}, {"ms", ms}, {"mtris_per_s", mtris}, {"sah", built.sah_cost}});
  }
  for (auto& v : vertices) v.pos[2] *= 1.5f;   // a deformation
  double refit_ms = best_ms(3, [&] { refit_blas(vertices, built); });
  std::printf("%-22s %12.1f %12.2f %10.2f\n", "refit", refit_ms, triangles.size() / (refit_ms * 1e3), built.sah_cost);
  out["refit"] = {{"ms", refit_ms}, {"sah", built.sah_cost}};

  std::printf("\nTLAS build (one BLAS instanced with random rotations)\n%-22s %12s\n", "instances", "ms");
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> pos(-5000.0f, 5000.0f), ang(0.0f, 6.2832f);
  for (int count : {100, 1000, 10000}) {
    std::vector<KInstance> instances(count);
    for (auto& inst : instances) {
      inst = KInstance{};
      float c = std::cos(ang(rng)), s = std::sin(ang(rng));
      float m[12] = {c, -s, 0, pos(rng), s, c, 0, pos(rng), 0, 0, 1, pos(rng)};
      std::memcpy(inst.object_to_world, m, sizeof m);
    }
    double ms = best_ms(5, [&] {
      auto copy = instances;
      build_tlas(copy, {built.nodes[0]});
    });
    std::printf("%-22d %12.3f\n", count, ms);
    out["tlas"].push_back({{"instances", count}, {"ms", ms}});
  }
  std::filesystem::path jp(json_path);
  if (jp.has_parent_path()) std::filesystem::create_directories(jp.parent_path());
  std::ofstream(jp) << out.dump(2) << "\n";
  std::printf("\nJSON: %s\n", json_path.c_str());
  return 0;
}
