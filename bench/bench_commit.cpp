// Commit buffer cost for 10 / 100 / 1000 moving entities: bytes per frame a tracer receives, records
// per frame, the core's sync time (transforms + TLAS rebuild + diff) and the tracer's apply time; also
// what a tracer that takes only every 4th commit receives, and what a full resync would weigh.
//
//   bench_commit [--frames N] [--json FILE]      (default: 240 frames, out/bench_commit.json)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cohort/commit/array_diff.h"
#include "cohort/commit/commit_channel.h"
#include "cohort/core/gpu_scene.h"
#include "cohort/core/world_sync.h"
#include "cohort/scene/render_world.h"

using namespace cohort;
using Clock = std::chrono::steady_clock;

namespace {

scene::Mesh box(const std::string& name, glm::vec3 half) {
  scene::Mesh m;
  m.name = name;
  for (int i = 0; i < 8; ++i) {
    scene::Vertex v;
    v.position = {(i & 1 ? 1 : -1) * half.x, (i & 2 ? 1 : -1) * half.y, (i & 4 ? 1 : -1) * half.z};
    m.vertices.push_back(v);
  }
  const uint32_t faces[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
  for (const auto& f : faces)
    for (uint32_t i : {f[0], f[1], f[2], f[0], f[2], f[3]}) m.indices.push_back(i);
  m.surfaces.push_back({0, 0, uint32_t(m.indices.size())});
  return m;
}

// A floor and `count` crates on a grid, each an entity of the same model, plus a few lights.
scene::Scene crate_field(int count) {
  scene::Scene s;
  s.name = "crate_field_" + std::to_string(count);
  scene::Material mat;
  mat.name = "textures/bench/crate";
  s.materials.push_back(mat);
  s.meshes.push_back(box("_area0", {4096, 4096, 8}));
  s.area_meshes.push_back(0);
  s.meshes.push_back(box("crate", {8, 8, 8}));
  int side = int(std::ceil(std::sqrt(double(count))));
  for (int i = 0; i < count; ++i) {
    scene::Entity e;
    e.name = "crate_" + std::to_string(i);
    e.mesh = 1;
    e.origin = {float(i % side) * 48.0f, float(i / side) * 48.0f, 16.0f};
    s.entities.push_back(e);
  }
  for (int i = 0; i < 4; ++i) {
    scene::Light l;
    l.name = "light_" + std::to_string(i);
    l.origin = {float(i) * 256.0f, 0.0f, 128.0f};
    s.lights.push_back(l);
  }
  return s;
}

struct Row {
  int entities = 0;
  double bytes_per_frame = 0, records_per_frame = 0, sync_ms = 0, apply_ms = 0, apply_ms_max = 0;
  double skip4_bytes_per_commit = 0;
  size_t full_resync_bytes = 0;
  bool converged = false;
};

size_t scene_bytes(const commit::TracerScene& s) {
  return s.vertices.size() * sizeof(KVertex) + s.vertex_colors.size() * sizeof(KVertexColor) +
         s.triangles.size() * sizeof(KTriangle) +
         s.blas_nodes.size() * sizeof(KBvhNode) + s.blases.size() * sizeof(KBlas) +
         s.instances.size() * sizeof(KInstance) + s.tlas_nodes.size() * sizeof(KBvhNode) +
         s.materials.size() * sizeof(KMaterial) + s.textures.size() * sizeof(KTexture) +
         s.texels.size() * sizeof(uint32_t) + s.lights.size() * sizeof(KLight) + sizeof(KCamera);
}

Row measure(int count, int frames) {
  scene::RenderWorld world(crate_field(count));
  core::WorldSync sync(world);
  // Two tracers' channels, as the Renderer keeps them: one takes every frame, one every fourth.
  auto every_frame = std::make_shared<commit::CommitChannel>(size_t(32) << 20, sync.snapshot(), 0);
  auto every_fourth = std::make_shared<commit::CommitChannel>(size_t(32) << 20, sync.snapshot(), 0);
  commit::TracerScene tracer, skipping;
  commit::apply_commit(every_frame->begin_frame(), tracer);
  commit::apply_commit(every_fourth->begin_frame(), skipping);
  Row row;
  row.entities = count;
  row.full_resync_bytes = scene_bytes(sync.master());
  double bytes = 0, records = 0, sync_ms = 0, apply_ms = 0, skip_bytes = 0;
  int skip_commits = 0;
  for (int f = 0; f < frames; ++f) {
    // Every crate bobs and turns.
    for (int h = 0; h < count; ++h) {
      scene::RenderEntity def = *world.EntityDef(h);
      float a = 0.05f * float(f) + 0.1f * float(h);
      def.origin.z = 16.0f + 8.0f * std::sin(a);
      def.axis = glm::mat3(glm::vec3(std::cos(a), std::sin(a), 0), glm::vec3(-std::sin(a), std::cos(a), 0),
                           glm::vec3(0, 0, 1));
      world.UpdateEntityDef(h, def);
    }
    scene::RenderView view;
    view.origin = {0, -200, 64};
    view.time_ms = f * 16;
    world.RenderScene(view);
    world.EndFrame();
    const commit::CommitBuffer frame_records = sync.sync(world.TakeChanges(), uint64_t(f + 1));
    for (const auto& channel : {every_frame, every_fourth})
      channel->publish(frame_records, [&] { return sync.snapshot(); });
    sync_ms += sync.last_stats().sync_ms;

    const commit::CommitBuffer& commit = every_frame->begin_frame();
    bytes += double(commit.bytes());
    records += double(commit.record_count());
    auto start = Clock::now();
    commit::apply_commit(commit, tracer);
    double ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    apply_ms += ms;
    row.apply_ms_max = std::max(row.apply_ms_max, ms);
    if ((f + 1) % 4 == 0) {
      const commit::CommitBuffer& c4 = every_fourth->begin_frame();
      skip_bytes += double(c4.bytes());
      ++skip_commits;
      commit::apply_commit(c4, skipping);
    }
  }
  row.bytes_per_frame = bytes / frames;
  row.records_per_frame = records / frames;
  row.sync_ms = sync_ms / frames;
  row.apply_ms = apply_ms / frames;
  row.skip4_bytes_per_commit = skip_commits ? skip_bytes / skip_commits : 0;
  commit::apply_commit(every_fourth->begin_frame(), skipping);
  row.converged = commit::same_tracer_scene(tracer, sync.master()) && commit::same_tracer_scene(skipping, sync.master());
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  int frames = 240;
  std::string json_path = "out/bench_commit.json";
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--frames" && i + 1 < argc) {
      frames = std::max(1, std::atoi(argv[++i]));
    } else if (a == "--json" && i + 1 < argc) {
      json_path = argv[++i];
    } else {
      std::fprintf(stderr, "usage: bench_commit [--frames N] [--json FILE]\n");
      return 2;
    }
  }
  std::printf("commit buffers: every entity moves every frame, %d frames\n\n", frames);
  std::printf("%9s %14s %10s %10s %10s %12s %16s %14s %9s\n", "entities", "bytes/frame", "records", "sync ms",
              "apply ms", "apply max ms", "skip-4 bytes/take", "full resync B", "converged");
  nlohmann::json out = {{"benchmark", "commit"}, {"frames", frames}, {"rows", nlohmann::json::array()}};
  bool ok = true;
  for (int count : {10, 100, 1000}) {
    Row r = measure(count, frames);
    ok &= r.converged;
    std::printf("%9d %14.0f %10.1f %10.3f %10.3f %12.3f %16.0f %14zu %9s\n", r.entities, r.bytes_per_frame,
                r.records_per_frame, r.sync_ms, r.apply_ms, r.apply_ms_max, r.skip4_bytes_per_commit,
                r.full_resync_bytes, r.converged ? "yes" : "NO");
    out["rows"].push_back({{"entities", r.entities},
                           {"bytes_per_frame", r.bytes_per_frame},
                           {"records_per_frame", r.records_per_frame},
                           {"sync_ms", r.sync_ms},
                           {"apply_ms", r.apply_ms},
                           {"apply_ms_max", r.apply_ms_max},
                           {"skip4_bytes_per_commit", r.skip4_bytes_per_commit},
                           {"full_resync_bytes", r.full_resync_bytes},
                           {"converged", r.converged}});
  }
  std::filesystem::path path(json_path);
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  std::ofstream(path) << out.dump(2) << "\n";
  std::printf("\nJSON: %s\n", json_path.c_str());
  return ok ? 0 : 1;
}
