// Dynamic workload scaling: picks samples per pixel (and, optionally, a render scale) so that frames
// take about target_ms. Frame time is assumed proportional to spp * scale^2. The controller smooths
// the measured time, acts only when it stays outside a dead band for a few frames, and steps up only
// when the predicted time of the next setting stays inside the band, so it settles instead of
// oscillating between two settings.
#pragma once

namespace cohort::core {

struct WorkloadScalerOptions {
  double target_ms = 33.3;
  double tolerance = 0.1;       // dead band: target * (1 +- tolerance)
  int min_spp = 1, max_spp = 64;
  bool scale_resolution = false;
  double min_scale = 0.5;       // render scale (fraction of width and height) when scale_resolution
  double scale_step = 0.1;
  int patience = 3;             // frames outside the band before acting
  double smoothing = 0.3;       // weight of the newest frame in the running mean
};

struct WorkloadSetting {
  int spp = 1;
  double render_scale = 1.0;
  bool operator==(const WorkloadSetting&) const = default;
};

class WorkloadScaler {
 public:
  explicit WorkloadScaler(WorkloadScalerOptions options, WorkloadSetting start = {});
  // Feed the time of a frame rendered with current(); returns the setting for the next frame.
  WorkloadSetting update(double frame_ms);
  WorkloadSetting current() const { return setting_; }
  double smoothed_ms() const { return smoothed_ms_; }

 private:
  double work(const WorkloadSetting& s) const { return s.spp * s.render_scale * s.render_scale; }
  WorkloadSetting faster(double ms_per_work) const;
  WorkloadSetting slower(double ms_per_work) const;
  void change_to(const WorkloadSetting& next);

  WorkloadScalerOptions options_;
  WorkloadSetting setting_;
  double smoothed_ms_ = 0.0;
  bool have_time_ = false;
  int over_ = 0, under_ = 0;
};

}  // namespace cohort::core
