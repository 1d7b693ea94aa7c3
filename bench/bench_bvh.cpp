// BVH benchmark: BLAS build throughput (Mtris/s, one thread and every thread) over the test map's world,
// the large generated map's world (when generated) and a synthetic terrain of >= 1M triangles; refit
// time; TLAS build time over 100/1,000/10,000 instances; SAH cost of each tree; map load and compile
// times. Prints a table and writes JSON.
//   bench_bvh [--triangles N] [--map PATH]... [--json PATH]
// Default maps: assets/testmap and, when generated (`cmake --build ... --target largemap`),
// build/default/assets/largemap. Wall time is what the targets are stated in; CPU time (process, all
// threads) is printed beside it, as wall time on a shared machine also counts other processes' load.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "cohort/core/bvh.h"
#include "cohort/core/gpu_scene.h"
#include "cohort/scene/map_loader.h"

using namespace cohort;
using namespace cohort::core;
using Clock = std::chrono::steady_clock;

namespace {

struct Mesh {
  std::string name;
  std::vector<KVertex> vertices;
  std::vector<KTriangle> triangles;
};

// A bumpy terrain grid: realistic, spatially coherent triangles (unlike a random soup).
Mesh make_terrain(int side) {
  Mesh m;
  m.name = "terrain";
  m.vertices.resize(size_t(side + 1) * (side + 1));
  for (int y = 0; y <= side; ++y)
    for (int x = 0; x <= side; ++x) {
      KVertex& v = m.vertices[size_t(y) * (side + 1) + x];
      v = KVertex{};
      v.pos[0] = float(x);
      v.pos[1] = float(y);
      v.pos[2] = 8.0f * std::sin(x * 0.05f) * std::cos(y * 0.07f);
    }
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x) {
      uint32_t a = uint32_t(y * (side + 1) + x), b = a + 1, c = a + uint32_t(side + 1), d = c + 1;
      m.triangles.push_back({a, c, b, 0});
      m.triangles.push_back({b, c, d, 0});
    }
  return m;
}

double cpu_ms() {
  timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return t.tv_sec * 1e3 + t.tv_nsec / 1e6;
}

struct Timing {
  double wall_ms = 1e30, cpu_ms = 1e30;   // best of the repeats, each
};

template <class F> Timing best_of(int repeats, F&& f) {
  Timing best;
  for (int i = 0; i < repeats; ++i) {
    const double c0 = cpu_ms();
    const auto t0 = Clock::now();
    f();
    best.wall_ms = std::min(best.wall_ms, std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
    best.cpu_ms = std::min(best.cpu_ms, cpu_ms() - c0);
  }
  return best;
}

// The world BLAS input exactly as WorldSync builds it: every area mesh in one triangle list.
Mesh world_mesh(const scene::Scene& map) {
  Mesh m;
  m.name = map.name;
  for (int mesh_index : map.area_meshes) {
    const scene::Mesh& mesh = map.meshes.at(size_t(mesh_index));
    const uint32_t base = uint32_t(m.vertices.size());
    for (const scene::Vertex& v : mesh.vertices) m.vertices.push_back(to_kvertex(v));
    std::vector<KTriangle> own = mesh_triangles(mesh, base, [](int material) { return uint32_t(material); });
    m.triangles.insert(m.triangles.end(), own.begin(), own.end());
  }
  return m;
}

void bench_blas(const Mesh& mesh, unsigned hw, nlohmann::json& out) {
  std::printf("\nBLAS build over %zu triangles (%s)\n%-22s %10s %10s %10s %10s %8s\n", mesh.triangles.size(),
              mesh.name.c_str(), "case", "wall ms", "cpu ms", "Mtris/s", "nodes", "SAH");
  nlohmann::json entry = {{"mesh", mesh.name}, {"triangles", mesh.triangles.size()}};
  const int repeats = mesh.triangles.size() > 2000000 ? 2 : 3;
  BlasBuild built;
  std::vector<int> thread_counts = {1};
  if (hw > 1) thread_counts.push_back(int(hw));
  for (int threads : thread_counts) {
    BvhBuildOptions options;
    options.threads = threads;
    Timing t = best_of(repeats, [&] { built = build_blas(mesh.vertices, mesh.triangles, options); });
    const double mtris = mesh.triangles.size() / (t.wall_ms * 1e3);
    std::printf("%-22s %10.1f %10.1f %10.2f %10zu %8.2f\n", ("build, " + std::to_string(threads) + " thread(s)").c_str(),
                t.wall_ms, t.cpu_ms, mtris, built.nodes.size(), built.sah_cost);
    entry["builds"].push_back({{"threads", threads}, {"wall_ms", t.wall_ms}, {"cpu_ms", t.cpu_ms},
                               {"mtris_per_s", mtris}, {"nodes", built.nodes.size()}, {"sah", built.sah_cost}});
  }
  std::vector<KVertex> moved = mesh.vertices;
  for (auto& v : moved) v.pos[2] *= 1.5f;   // a deformation
  Timing refit = best_of(repeats, [&] { refit_blas(moved, built); });
  std::printf("%-22s %10.1f %10.1f %10.2f %10s %8.2f\n", "refit (deformed)", refit.wall_ms, refit.cpu_ms,
              mesh.triangles.size() / (refit.wall_ms * 1e3), "", built.sah_cost);
  entry["refit"] = {{"wall_ms", refit.wall_ms}, {"cpu_ms", refit.cpu_ms}, {"sah", built.sah_cost}};
  out["blas"].push_back(entry);
}

void bench_tlas(const KBvhNode& blas_root, nlohmann::json& out) {
  std::printf("\nTLAS build (one BLAS instanced with random rotations), median and best of 51; refit after every\n"
              "instance moved by up to 16 units (what WorldSync does while entities only move)\n"
              "%-22s %10s %10s %10s %12s %10s\n",
              "instances", "median ms", "best ms", "SAH", "refit ms", "refit SAH");
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
    std::vector<double> ms;
    std::vector<KBvhNode> tlas;
    for (int r = 0; r < 51; ++r) {
      auto copy = instances;   // build_tlas reorders its input
      const auto t0 = Clock::now();
      tlas = build_tlas(copy, {blas_root});
      ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
    }
    std::sort(ms.begin(), ms.end());
    const float sah = sah_cost(tlas);
    auto ordered = instances;
    tlas = build_tlas(ordered, {blas_root});
    std::uniform_real_distribution<float> step(-16.0f, 16.0f);
    std::vector<double> refit_ms;
    float refit_sah = sah;
    for (int r = 0; r < 51; ++r) {
      for (auto& inst : ordered)
        for (int axis = 0; axis < 3; ++axis) inst.object_to_world[4 * axis + 3] += step(rng);
      const auto t0 = Clock::now();
      refit_sah = refit_tlas(ordered, {blas_root}, tlas);
      refit_ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
    }
    std::sort(refit_ms.begin(), refit_ms.end());
    std::printf("%-22d %10.3f %10.3f %10.2f %12.3f %10.2f\n", count, ms[ms.size() / 2], ms[0], sah,
                refit_ms[refit_ms.size() / 2], refit_sah);
    out["tlas"].push_back({{"instances", count}, {"median_ms", ms[ms.size() / 2]}, {"best_ms", ms[0]}, {"sah", sah},
                           {"refit_median_ms", refit_ms[refit_ms.size() / 2]}, {"refit_sah", refit_sah}});
  }
}

}  // namespace

int main(int argc, char** argv) {
  int triangles_wanted = 1000000;
  std::string json_path = "out/bench_bvh.json";
  std::vector<std::string> maps;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--triangles" && i + 1 < argc) triangles_wanted = std::stoi(argv[++i]);
    else if (a == "--json" && i + 1 < argc) json_path = argv[++i];
    else if (a == "--map" && i + 1 < argc) maps.push_back(argv[++i]);
    else {
      std::fprintf(stderr, "usage: bench_bvh [--triangles N] [--map PATH]... [--json PATH]\n");
      return 2;
    }
  }
  if (maps.empty()) {
    maps.push_back(std::string(COHORT_SOURCE_DIR) + "/assets/testmap/maps/testmap.map");
    const std::string large = std::string(COHORT_SOURCE_DIR) + "/build/default/assets/largemap/maps/largemap.map";
    if (std::filesystem::exists(large)) maps.push_back(large);
    else std::printf("(large map not generated: cmake --build --preset default --target largemap)\n");
  }
  const unsigned hw = std::max(1u, std::thread::hardware_concurrency());
  nlohmann::json out;
  out["machine_threads"] = hw;
  std::printf("bench_bvh: %u hardware threads\n", hw);

  for (const std::string& path : maps) {
    scene::Vfs vfs;
    const auto t0 = Clock::now();
    scene::Scene map = scene::load_map(vfs, path);
    const double load_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    const auto t1 = Clock::now();
    CompiledScene compiled = compile_scene(map);
    const double compile_ms = std::chrono::duration<double, std::milli>(Clock::now() - t1).count();
    std::printf("\nmap %s: load %.0f ms, compile_scene (textures, materials, every BVH) %.0f ms\n", map.name.c_str(),
                load_ms, compile_ms);
    out["maps"].push_back({{"map", map.name}, {"load_ms", load_ms}, {"compile_ms", compile_ms}});
    bench_blas(world_mesh(map), hw, out);
  }

  const Mesh terrain = make_terrain(int(std::ceil(std::sqrt(triangles_wanted / 2.0))));
  bench_blas(terrain, hw, out);
  BlasBuild terrain_blas = build_blas(terrain.vertices, terrain.triangles);
  bench_tlas(terrain_blas.nodes[0], out);

  std::filesystem::path jp(json_path);
  if (jp.has_parent_path()) std::filesystem::create_directories(jp.parent_path());
  std::ofstream(jp) << out.dump(2) << "\n";
  std::printf("\nJSON: %s\n", json_path.c_str());
  return 0;
}
