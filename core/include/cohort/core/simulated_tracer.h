// A stand-in tracer for balancing experiments and tests: its band time is the summed cost of its rows
// under a scene cost model (which follows the camera's yaw, like spinning in the Aztec test of the
// Brigade paper, §5) divided by its speed, with seeded noise. On the virtual clock it reports that
// time without waiting (fast, reproducible CI); on the sleep/spin clocks it really takes that long.
#pragma once

#include <cstdint>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "cohort/core/tracer.h"

namespace cohort::core {

// Per-row render cost of a synthetic panorama: a floor/wall/ceiling base plus objects at fixed yaw
// angles that add cost to the rows they cover while they are inside the horizontal field of view.
class SpinSceneCostModel {
 public:
  explicit SpinSceneCostModel(uint64_t seed = 1, int objects = 24, float fov_degrees = 90.0f);
  // Cost of each row of a `rows`-row frame seen at `yaw_radians`; one unit is about a plain wall row.
  std::vector<double> row_costs(double yaw_radians, int rows) const;
  double band_cost(double yaw_radians, int rows, int row_begin, int row_end) const;

 private:
  struct Object {
    double yaw, half_width;   // radians
    double top, bottom;       // fraction of frame height
    double density;           // extra cost per row when fully in view
  };
  double row_base(double v) const;
  std::vector<Object> objects_;
  double half_fov_;
};

// Yaw of a camera looking along `forward` (Doom: Z up, yaw measured in the XY plane).
double camera_yaw(const KCamera& camera);
// A camera at the origin of the given size looking horizontally at `yaw_radians` (core/view.h).
KCamera spin_camera(int width, int height, double yaw_radians);

enum class SimulatedClock { virtual_time, sleep, spin };

struct SimulatedTracerOptions {
  std::string name = "sim";
  double speed = 1.0;              // relative device speed (2 = twice as fast)
  double noise = 0.0;              // relative standard deviation of each band time
  uint64_t seed = 1;
  double ms_per_cost = 0.05;       // milliseconds per cost unit at speed 1
  // Per rendered band, whatever its size: what a real tracer pays outside the rows themselves (kernel
  // launch, upload, band copy, synchronisation). Not scaled by speed; noise applies to it too.
  double fixed_ms = 0.0;
  SimulatedClock clock = SimulatedClock::virtual_time;
  double time_scale = 1.0;         // sleep/spin clocks wait time_scale * band time
  // Report a per-row work count (BandResult::row_work) like a kernel counting rays per row: the true
  // row cost distorted by a fixed per-row error and a per-frame one, each of relative size row_work_error.
  bool report_row_work = false;
  double row_work_error = 0.2;
  std::set<uint64_t> throw_on_frames;  // render_band throws on these frame indices
  std::set<uint64_t> throw_on_commits; // apply throws on commits of these frames (incremental ones only)
  std::set<uint64_t> hang_on_frames;   // render_band blocks for hang_ms (real time) on these frames
  double hang_ms = 0.0;
  // Keep a scene copy like a real tracer: every commit is applied to it (commit::apply_commit), so
  // tests can compare it with the master.
  bool keep_scene = false;
};

class SimulatedTracer final : public Tracer {
 public:
  SimulatedTracer(std::shared_ptr<const SpinSceneCostModel> model, SimulatedTracerOptions options);
  std::string name() const override { return options_.name; }
  void apply(const commit::CommitBuffer& commit) override;
  // Writes every pixel of its rows as (frame_index, tag, 1, 1), tag = seed, so tests can see who
  // delivered each row; returns the simulated time as device_ms.
  using Tracer::render_band;
  BandResult render_band(const BandJob& job, BandBuffer& target) override;

  uint64_t commits_applied() const { return commits_applied_; }
  uint64_t last_commit_frame() const { return last_commit_frame_; }
  uint64_t full_resyncs_applied() const { return full_resyncs_applied_; }
  // With keep_scene: the scene as the commits applied so far built it. Read it only while the tracer
  // is not running a job (e.g. between Renderer frames).
  const commit::TracerScene& scene() const { return scene_; }

 private:
  std::shared_ptr<const SpinSceneCostModel> model_;
  SimulatedTracerOptions options_;
  uint64_t commits_applied_ = 0;
  uint64_t last_commit_frame_ = 0;
  uint64_t full_resyncs_applied_ = 0;
  commit::TracerScene scene_;
};

}  // namespace cohort::core
