#include "cohort/core/simulated_tracer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>
#include <thread>

#include "cohort/core/view.h"

namespace cohort::core {

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// Length of the overlap of two arcs given by centre and half width, on the circle.
double arc_overlap(double centre_a, double half_a, double centre_b, double half_b) {
  double d = std::fmod(std::abs(centre_a - centre_b), kTwoPi);
  if (d > std::numbers::pi) d = kTwoPi - d;
  const double lo = std::max(-half_a, d - half_b), hi = std::min(half_a, d + half_b);
  return std::max(0.0, hi - lo);
}

uint64_t mix(uint64_t x) {  // splitmix64 finaliser: independent streams per (seed, frame)
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

}  // namespace

SpinSceneCostModel::SpinSceneCostModel(uint64_t seed, int objects, float fov_degrees)
    : half_fov_(fov_degrees * std::numbers::pi / 360.0) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int i = 0; i < objects; ++i) {
    Object o;
    o.yaw = unit(rng) * kTwoPi;
    o.half_width = (5.0 + 40.0 * unit(rng)) * std::numbers::pi / 360.0;
    const double a = 0.15 + 0.8 * unit(rng), b = 0.15 + 0.8 * unit(rng);
    o.top = std::min(a, b);
    o.bottom = std::max(std::max(a, b), o.top + 0.05);
    o.density = 0.5 + 3.5 * unit(rng);
    objects_.push_back(o);
  }
}

double SpinSceneCostModel::row_base(double v) const {
  if (v < 0.3) return 0.5;   // ceiling/sky: rays escape or hit one big polygon
  if (v < 0.65) return 1.0;  // walls
  return 0.8;                // floor
}

std::vector<double> SpinSceneCostModel::row_costs(double yaw, int rows) const {
  std::vector<double> cost(static_cast<size_t>(std::max(rows, 0)));
  for (int r = 0; r < rows; ++r) cost[static_cast<size_t>(r)] = row_base((r + 0.5) / rows);
  for (const Object& o : objects_) {
    const double visible = arc_overlap(yaw, half_fov_, o.yaw, o.half_width) / (2.0 * half_fov_);
    if (visible <= 0.0) continue;
    const int first = static_cast<int>(o.top * rows), last = static_cast<int>(o.bottom * rows);
    for (int r = std::max(first, 0); r < std::min(last, rows); ++r) cost[static_cast<size_t>(r)] += o.density * visible;
  }
  return cost;
}

double SpinSceneCostModel::band_cost(double yaw, int rows, int row_begin, int row_end) const {
  const std::vector<double> cost = row_costs(yaw, rows);
  double sum = 0.0;
  for (int r = std::max(row_begin, 0); r < std::min(row_end, rows); ++r) sum += cost[static_cast<size_t>(r)];
  return sum;
}

double camera_yaw(const KCamera& camera) { return std::atan2(camera.forward[1], camera.forward[0]); }

KCamera spin_camera(int width, int height, double yaw) {
  return make_camera(glm::vec3(0.0f), ViewAngles{static_cast<float>(yaw * 180.0 / std::numbers::pi), 0.0f},
                     kDefaultFovX, width, height);
}

SimulatedTracer::SimulatedTracer(std::shared_ptr<const SpinSceneCostModel> model, SimulatedTracerOptions options)
    : model_(std::move(model)), options_(std::move(options)) {
  if (!model_) throw std::invalid_argument("SimulatedTracer: no cost model");
  if (!(options_.speed > 0.0)) throw std::invalid_argument("SimulatedTracer '" + options_.name + "': speed must be > 0");
  if (!(options_.fixed_ms >= 0.0)) throw std::invalid_argument("SimulatedTracer '" + options_.name + "': fixed_ms must be >= 0");
}

void SimulatedTracer::apply(const commit::CommitBuffer& commit) {
  if (!commit.is_full_resync() && options_.throw_on_commits.count(commit.frame()))
    throw std::runtime_error(options_.name + ": simulated commit that does not fit, frame " + std::to_string(commit.frame()));
  if (options_.keep_scene) commit::apply_commit(commit, scene_);
  if (commit.is_full_resync()) ++full_resyncs_applied_;
  ++commits_applied_;
  last_commit_frame_ = commit.frame();
}

BandResult SimulatedTracer::render_band(const BandJob& job, BandBuffer& target) {
  const uint64_t frame = job.params.frame_index;
  if (options_.throw_on_frames.count(frame))
    throw std::runtime_error(options_.name + ": simulated device fault on frame " + std::to_string(frame));
  if (options_.hang_on_frames.count(frame))
    std::this_thread::sleep_for(std::chrono::duration<double, std::milli>(options_.hang_ms));

  const int rows = static_cast<int>(job.camera.height);
  const int begin = static_cast<int>(job.params.row_begin), end = static_cast<int>(job.params.row_end);
  const std::vector<double> costs = model_->row_costs(camera_yaw(job.camera), rows);
  double band_cost = 0.0;
  for (int r = std::max(begin, 0); r < std::min(end, rows); ++r) band_cost += costs[static_cast<size_t>(r)];
  double ms = end > begin ? options_.fixed_ms + band_cost * options_.ms_per_cost / options_.speed : 0.0;
  if (options_.noise > 0.0) {
    std::mt19937_64 rng(mix(options_.seed * 0x100000001b3ull ^ frame));
    std::normal_distribution<double> gauss(0.0, options_.noise);
    ms *= std::max(0.05, 1.0 + gauss(rng));
  }
  std::vector<float> row(static_cast<size_t>(target.width()) * 4);
  for (size_t x = 0; x < row.size(); x += 4) {
    row[x + 0] = static_cast<float>(frame);
    row[x + 1] = static_cast<float>(options_.seed);
    row[x + 2] = 1.0f;
    row[x + 3] = 1.0f;
  }
  for (int r = std::max(begin, 0); r < std::min(end, target.height()); ++r)
    target.store(r, 0, row.data(), static_cast<size_t>(target.width()), static_cast<uint32_t>(frame));
  const auto wait = std::chrono::duration<double, std::milli>(ms * options_.time_scale);
  if (options_.clock == SimulatedClock::sleep) {
    std::this_thread::sleep_for(wait);
  } else if (options_.clock == SimulatedClock::spin) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(wait);
    while (std::chrono::steady_clock::now() < until) {
    }
  }
  BandResult result;
  result.device_ms = ms;
  if (options_.report_row_work && end > begin) {
    // The fixed part depends only on the row, so every tracer miscounts a row the same way.
    std::normal_distribution<double> gauss(0.0, 1.0);
    std::mt19937_64 fresh(mix(options_.seed ^ (frame * 0x9e3779b97f4a7c15ull) ^ 0x5a5a));
    result.row_work.resize(static_cast<size_t>(end - begin));
    for (int r = begin; r < end; ++r) {
      std::mt19937_64 fixed(mix(0xc0ffee ^ static_cast<uint64_t>(r)));
      const double error = options_.row_work_error * (0.7 * gauss(fixed) + 0.7 * gauss(fresh));
      const double cost = r >= 0 && r < rows ? costs[static_cast<size_t>(r)] : 0.0;
      result.row_work[static_cast<size_t>(r - begin)] = static_cast<float>(cost * std::max(0.1, 1.0 + error));
    }
  }
  return result;
}

}  // namespace cohort::core
