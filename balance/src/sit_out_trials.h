// Whole Cost's end-to-end check of its small takers (BalancerOptions::frame_trials): a decorator
// that now and then hands a small taker's rows to the others for a few frames, compares the frame
// interval with and without it, and keeps it out when it does not make frames faster.
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <set>
#include <vector>

#include "cohort/balance/balancer.h"

namespace cohort::balance {

class SitOutTrials final : public Balancer {
 public:
  SitOutTrials(std::unique_ptr<Balancer> inner, const BalancerOptions& options);
  std::string name() const override { return inner_->name(); }
  std::vector<Band> divide(const DivideInput& in) override;
  BandRules band_rules() const override;
  std::vector<Band> probe_bands() const override { return probes_; }
  std::vector<SitOutVerdict> take_verdicts() override;
  void reset() override;

 private:
  struct Trial {
    int tracer = 0;
    int frame = 0;                         // frames of the trial begun so far
    std::vector<double> with, without;     // intervals counted in each mode
  };
  void record_interval(double interval_ms);
  void finish_trial();
  void start_trial_if_due(const DivideInput& in, const std::vector<Band>& bands);
  void forget_state();

  std::unique_ptr<Balancer> inner_;
  BalancerOptions options_;
  int rows_ = -1;
  int frames_ = 0;                     // divisions since the last reset
  std::optional<Trial> trial_;
  int counted_window_frame_ = -1;      // the previous frame's place in its trial window (-1: not in a trial)
  bool previous_without_ = false;      // whether the previous frame ran without the trial's tracer
  std::set<int> sitting_out_;          // by verdict, until their next trial
  std::map<int, int> next_trial_at_;   // tracer id -> frames_ when it may be tried (again)
  std::map<int, int> small_for_;       // tracer id -> frames in a row it has been a small taker
  std::vector<Band> probes_;
  std::vector<SitOutVerdict> verdicts_;
};

// `bands` (contiguous, covering [0, rows)) with the rows of the bands marked in `drop` handed to the
// other non-empty bands in proportion to their rows, cuts on multiples of `row_unit`; dropped bands
// become empty in place. Unchanged when nothing else would be left to render.
std::vector<Band> without_bands(const std::vector<Band>& bands, const std::vector<bool>& drop, int rows, int row_unit);

}  // namespace cohort::balance
