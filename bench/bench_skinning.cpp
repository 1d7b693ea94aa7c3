// Skinned characters per frame: the core's sync (the master's skin + refit, the TLAS, the records), the
// bytes a tracer receives (joints, not vertices), the host skin + BLAS refit a CPU tracer runs
// (commit::skin_on_host over TBB), and whole tracer applies: Embree (host skinning plus its geometry
// refit and instance scene) and any CUDA/OpenCL tracer named (skinning kernels on the device).
//
//   bench_skinning [--characters N] [--vertices V] [--joints J] [--frames F]
//                  [--tracers embree,cuda:0,opencl:0] [--json out/bench_skinning.json]
//
// The character is generated: a tube of rings along a chain of J joints, each vertex weighted by the two
// nearest joints, bending as a wave runs along the chain (every joint moves every frame).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "cohort/balance/order_statistics.h"
#include "cohort/commit/commit_buffer.h"
#include "cohort/commit/host_skinning.h"
#include "cohort/core/tracer.h"
#include "cohort/core/world_sync.h"
#include "cohort/scene/md5.h"
#include "cohort/scene/render_world.h"
#include "cohort/tracers/tracer_registry.h"

using namespace cohort;
using Clock = std::chrono::steady_clock;

namespace {

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

constexpr float kSegment = 8.0f;

// A tube along +Z: `rings` rings of `sides` vertices; joint j sits at height j * kSegment.
scene::Md5Mesh tube_character(int target_vertices, int joints) {
  scene::Md5Mesh mesh;
  mesh.file = "generated_tube.md5mesh";
  for (int j = 0; j < joints; ++j) {
    scene::Md5Joint joint;
    joint.name = "joint" + std::to_string(j);
    joint.parent = j - 1;
    joint.bind.position = {0.0f, 0.0f, float(j) * kSegment};
    mesh.joints.push_back(joint);
  }
  const int sides = 32;
  const int rings = std::max(2, target_vertices / sides);
  const float height = float(joints - 1) * kSegment;
  scene::Md5MeshPart part;
  part.shader = "models/bench/skin";
  for (int r = 0; r < rings; ++r) {
    const float z = height * float(r) / float(rings - 1);
    const float along = z / kSegment;
    const int j0 = std::min(int(along), joints - 1), j1 = std::min(j0 + 1, joints - 1);
    const float t = j1 == j0 ? 0.0f : along - float(j0);
    for (int s = 0; s < sides; ++s) {
      const float a = 2.0f * 3.14159265f * float(s) / float(sides);
      const glm::vec3 p(6.0f * std::cos(a), 6.0f * std::sin(a), z);
      scene::Md5Vert v;
      v.st = {float(s) / float(sides), float(r) / float(rings - 1)};
      v.first_weight = int(part.weights.size());
      for (auto [j, bias] : {std::pair{j0, 1.0f - t}, std::pair{j1, t}}) {
        if (bias <= 0.0f && v.weight_count > 0) continue;
        scene::Md5Weight w;
        w.joint = j;
        w.bias = bias;
        w.offset = p - mesh.joints[size_t(j)].bind.position;
        part.weights.push_back(w);
        ++v.weight_count;
      }
      part.verts.push_back(v);
    }
  }
  for (int r = 0; r + 1 < rings; ++r)
    for (int s = 0; s < sides; ++s) {
      const uint32_t a = uint32_t(r * sides + s), b = uint32_t(r * sides + (s + 1) % sides);
      const uint32_t c = a + uint32_t(sides), d = b + uint32_t(sides);
      for (uint32_t i : {a, c, b, b, c, d}) part.indices.push_back(i);
    }
  mesh.parts.push_back(std::move(part));
  return mesh;
}

// Model space pose at time t: each joint bends the chain a little about X, a wave running along it.
std::vector<scene::JointTransform> wave_pose(int joints, double t, int character) {
  std::vector<scene::JointTransform> pose(static_cast<size_t>(joints));
  glm::quat rotation(1.0f, 0.0f, 0.0f, 0.0f);
  glm::vec3 position(0.0f);
  for (int j = 0; j < joints; ++j) {
    if (j > 0) position += rotation * glm::vec3(0.0f, 0.0f, kSegment);
    const float bend = 0.12f * float(std::sin(3.0 * t - 0.4 * j + character));
    rotation = glm::normalize(rotation * glm::angleAxis(bend, glm::vec3(1.0f, 0.0f, 0.0f)));
    pose[size_t(j)] = {rotation, position};
  }
  return pose;
}

struct Series {
  std::vector<double> values;
  void add(double v) { values.push_back(v); }
  double median() const { return cohort::median(values); }
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Skinned characters: skin + BLAS refit per character per frame, and the bytes that travel"};
  int characters = 4, vertices = 8192, joints = 64, frames = 60;
  std::string tracer_list = "embree";
  std::string json_path = "out/bench_skinning.json";
  app.add_option("--characters", characters, "characters posed every frame")->check(CLI::Range(1, 4096));
  app.add_option("--vertices", vertices, "vertices per character (rounded to whole rings of 32)")
      ->check(CLI::Range(64, 4 << 20));
  app.add_option("--joints", joints, "joints per character")->check(CLI::Range(2, 4096));
  app.add_option("--frames", frames, "frames timed (medians are reported)")->check(CLI::Range(1, 100000));
  app.add_option("--tracers", tracer_list, "tracers whose apply() is timed, e.g. embree,cuda:0");
  app.add_option("--json", json_path, "JSON output");
  CLI11_PARSE(app, argc, argv);

  const scene::Md5Mesh md5 = tube_character(vertices, joints);
  scene::Scene s;
  s.name = "bench_skinning";
  scene::Mesh mesh = scene::skin_md5(md5, scene::bind_pose(md5)).mesh;
  mesh.skin = std::make_shared<const scene::MeshSkin>(scene::md5_mesh_skin(md5));
  const size_t vertex_count = mesh.vertices.size(), triangle_count = mesh.triangle_count();
  s.meshes.push_back(std::move(mesh));
  for (int c = 0; c < characters; ++c) {
    scene::Entity e;
    e.name = "character_" + std::to_string(c);
    e.mesh = 0;
    e.origin = {float(c % 16) * 48.0f, float(c / 16) * 48.0f, 0.0f};
    s.entities.push_back(e);
  }
  scene::RenderWorld world(std::move(s));
  core::WorldSync sync(world);
  world.TakeChanges();
  auto pose_all = [&](double t) {
    for (int c = 0; c < characters; ++c) {
      scene::RenderEntity def = *world.EntityDef(c);
      def.joints = wave_pose(joints, t, c);
      world.UpdateEntityDef(c, def);
    }
  };

  std::vector<std::unique_ptr<core::Tracer>> tracers;
  for (const tracers::TracerSpec& spec : tracers::parse_tracer_list(tracer_list)) {
    try {
      tracers.push_back(tracers::make_tracer(spec));
    } catch (const std::exception& e) {
      std::printf("skipping %s: %s\n", spec.kind.c_str(), e.what());
    }
  }
  // Frame 0 creates the characters' BLASes and skins (a one-off upload); the copies start from it.
  pose_all(0.0);
  commit::CommitBuffer first = sync.sync(world.TakeChanges(), 1);
  const size_t setup_bytes = first.bytes();
  commit::TracerScene host_copy = *sync.snapshot();
  for (auto& t : tracers) t->apply(commit::CommitBuffer::full(sync.snapshot(), 1));

  Series sync_ms, host_skin_ms, bytes, joint_bytes;
  std::map<std::string, Series> apply_ms;
  uint32_t rebuilds = 0;
  for (int f = 0; f < frames; ++f) {
    pose_all(double(f + 1) / 60.0);
    auto start = Clock::now();
    commit::CommitBuffer records = sync.sync(world.TakeChanges(), uint64_t(f + 2));
    sync_ms.add(ms_since(start));
    rebuilds += sync.last_stats().skin_rebuilds;
    bytes.add(double(records.bytes()));
    size_t joint_record_bytes = 0;
    for (const auto& [skin, js] : records.skin_joints()) joint_record_bytes += commit::kRecordHeaderBytes + js.size() * sizeof(KJoint);
    joint_bytes.add(double(joint_record_bytes));
    start = Clock::now();
    commit::apply_commit(records, host_copy, commit::Skinning::on_host);
    host_skin_ms.add(ms_since(start));
    for (auto& t : tracers) {
      start = Clock::now();
      t->apply(records);
      apply_ms[t->name()].add(ms_since(start));
    }
  }

  const double per_char = 1.0 / double(characters);
  std::printf("characters %d, %zu vertices, %zu triangles and %d joints each, %d frames (medians)\n", characters,
              vertex_count, triangle_count, joints, frames);
  std::printf("setup commit (BLASes, weights, adjacency): %.1f KiB\n", double(setup_bytes) / 1024.0);
  std::printf("%-44s %12s %14s %12s %12s\n", "stage", "ms/frame", "ms/character", "Mvert/s", "Mjoint/s");
  auto row = [&](const std::string& name, double ms) {
    const double mverts = ms > 0 ? double(vertex_count) * characters / (ms * 1e3) : 0.0;
    const double mjoints = ms > 0 ? double(joints) * characters / (ms * 1e3) : 0.0;
    std::printf("%-44s %12.3f %14.4f %12.2f %12.3f\n", name.c_str(), ms, ms * per_char, mverts, mjoints);
  };
  row("core sync (master skin + refit, TLAS, records)", sync_ms.median());
  row("host skin + BLAS refit (apply_commit on host)", host_skin_ms.median());
  for (const auto& [name, series] : apply_ms) row("apply on " + name, series.median());
  std::printf("delta bytes per frame %.0f (%.0f per character; joint records %.0f per character; a vertex upload "
              "would be %zu)\n",
              bytes.median(), bytes.median() * per_char, joint_bytes.median() * per_char, vertex_count * sizeof(KVertex));
  std::printf("BLAS rebuilds for SAH decay: %u\n", rebuilds);

  nlohmann::json out;
  out["characters"] = characters;
  out["vertices_per_character"] = vertex_count;
  out["triangles_per_character"] = triangle_count;
  out["joints_per_character"] = joints;
  out["frames"] = frames;
  out["setup_bytes"] = setup_bytes;
  out["sync_ms"] = sync_ms.median();
  out["host_skin_refit_ms"] = host_skin_ms.median();
  out["bytes_per_frame"] = bytes.median();
  out["bytes_per_character_per_frame"] = bytes.median() * per_char;
  out["joint_bytes_per_character_per_frame"] = joint_bytes.median() * per_char;
  out["blas_rebuilds"] = rebuilds;
  for (const auto& [name, series] : apply_ms) out["apply_ms"][name] = series.median();
  std::filesystem::path path(json_path);
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  std::ofstream(path) << out.dump(2) << "\n";
  std::printf("wrote %s\n", json_path.c_str());
  return 0;
}
