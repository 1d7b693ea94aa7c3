// One tracer's band time as a fixed part plus a part that grows with the band's work:
// ms = fixed_ms + work * ms_per_work. The fixed part (launch, upload, band copy, commit apply) is what
// Perfect's rows / ms hides: it makes a tracer with a small band look slow per row, and it is why a
// very slow tracer can make the frame slower with any band at all.
#pragma once

#include <deque>

namespace cohort::balance {

class AffineTimeFit {
 public:
  // `follow`: how fast the per-work cost follows the newest measurement (1 = newest only); the view
  // changes what a row costs from frame to frame, the fixed part does not.
  explicit AffineTimeFit(double follow) : follow_(follow) {}

  // One measured band. A time far off the prediction (a hiccup) is clipped before it is learnt.
  void add(double work, double ms);
  bool known() const { return known_; }
  double fixed_ms() const { return fixed_ms_; }
  double ms_per_work() const { return ms_per_work_; }
  double predict(double work) const { return fixed_ms_ + work * ms_per_work_; }

 private:
  struct Sample {
    double work, ms;
  };
  void refit_fixed();

  double follow_;
  bool known_ = false;
  double fixed_ms_ = 0.0;
  double ms_per_work_ = 0.0;
  double spread_ = 0.0;            // smoothed |relative residual|, for clipping hiccups
  std::deque<Sample> samples_;     // the newest last
};

}  // namespace cohort::balance
