// Balancers size every tracer's row band for the next frame from what the previous frame measured
// (Brigade, §4.3-4.5). They are pure and single-threaded: the core calls divide() once per frame.
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "cohort/balance/bands.h"

namespace cohort::balance {

// What one tracer did last frame.
struct TracerMeasurement {
  int tracer = 0;   // stable id of the tracer (survives other tracers joining or leaving)
  Band band;        // the rows it rendered
  double ms = 0.0;  // how long that took; <= 0 means "not measured" and is ignored
};

struct DivideInput {
  int rows = 0;                                // rows in the frame to divide
  std::vector<int> tracers;                    // ids taking part this frame, in band order (top first)
  std::vector<TracerMeasurement> previous;     // last frame; may lack ids (new, dropped) or hold extra ones (removed)
  std::vector<float> row_cost_proxy;           // optional per-row relative cost estimate (size == rows), e.g.
                                               // last frame's per-row sample count; empty when there is none
  double last_interval_ms = 0.0;               // wall time from the previous frame's start to this one's: the
                                               // delivered-frame interval of a steady loop; 0 when unknown
                                               // (a virtual clock), which leaves sit-out trials off
};

// What a sit-out trial found: the frame interval with a small taker rendering its share and with its
// rows handed to the others (medians over the trial's frames), and what was decided.
struct SitOutVerdict {
  int tracer = 0;
  double with_ms = 0.0;
  double without_ms = 0.0;
  int frames_each = 0;       // intervals behind each median
  bool sits_out = false;     // true: no rows (and no probes) until the next trial
  int next_trial_in = 0;     // frames until it is tried again
};

class Balancer {
 public:
  virtual ~Balancer() = default;
  virtual std::string name() const = 0;
  // One band per entry of in.tracers, in that order, covering [0, in.rows) (see check_bands() with
  // band_rules()).
  virtual std::vector<Band> divide(const DivideInput& in) = 0;
  // The rules divide() keeps: the paper's 4-row units and non-empty bands unless a balancer says otherwise.
  virtual BandRules band_rules() const { return {}; }
  // After divide(): for each entry of in.tracers, rows it should render on the side, unwaited and
  // thrown away, only to be measured (a tracer the balancer benched, probed now and then to see
  // whether it is worth rows again); its time comes back in a later DivideInput::previous with that
  // band. Empty (or all bands empty) when nothing is to be probed.
  virtual std::vector<Band> probe_bands() const { return {}; }
  // Verdicts of sit-out trials reached since the last call (whole-cost with frame_trials), for the log.
  virtual std::vector<SitOutVerdict> take_verdicts() { return {}; }
  // Forget everything learnt (a cut, a resolution change). Balancers also reset themselves when the
  // row count changes.
  virtual void reset() = 0;
};

struct BalancerOptions {
  // Perfect Smooth (eq. 2): weight of the new Perfect division; 1 - alpha stays with last frame's
  // division. 0.5 halves the error each frame with a steady cost, damping Perfect's oscillation.
  double alpha = 0.5;
  // Robin Hood: work units moved from the slowest to the fastest tracer per frame.
  int robin_hood_units = 2;
  // Row Cost: how fast the per-unit cost map follows band times when there is no per-row work proxy
  // (1 = last frame only), and how fast per-tracer speeds follow new measurements. Speeds are
  // hardware properties, so they are smoothed hard, which cancels timing noise. Chosen by
  // `cohort bench balance` sweeps (see docs/balancing.md).
  double cost_rate = 0.5;
  double speed_rate = 0.1;
  // Whole Cost: a tracer is benched (zero rows) when the frame is predicted less than this fraction
  // faster with it than without (a tiny share buys little and adds its timing noise and hand-over
  // at the end of the frame); a benched tracer is probed every probe_interval frames; bands smaller
  // than fine_below_rows are cut on single rows instead of 4-row units (false: 4-row units always).
  double min_gain = 0.03;
  int probe_interval = 30;
  int fine_below_rows = 32;
  bool fine_cuts = true;
  // Whole Cost's sit-out trials. Its model sees each tracer's band time, not what a tracer costs the
  // others (a CPU tracer's threads slow the host's merge and the GPU drivers' threads): so a taker with
  // at most trial_share of the rows, and at most half an even share, for trial_window frames in a row (not
  // a share that dips for a frame or two while the split settles), is tried out end to end. Windows of
  // trial_window frames alternate, its share rendered / its rows handed to the others in proportion,
  // trial_pairs times; the first
  // trial_settle intervals of each window are not counted (the pipeline still carries the other mode).
  // It keeps its rows only when the median interval is at least trial_min_gain shorter with it; either
  // way it is tried again after trial_every frames. Needs DivideInput::last_interval_ms.
  bool frame_trials = true;
  double trial_share = 0.2;
  int trial_window = 8;
  int trial_settle = 2;
  int trial_pairs = 4;
  double trial_min_gain = 0.01;
  int trial_warmup = 60;
  int trial_every = 600;
};

// "none", "robin-hood", "perfect", "perfect-smooth", "row-cost", "whole-cost". Throws std::invalid_argument naming
// the known balancers for any other name.
std::unique_ptr<Balancer> make_balancer(std::string_view name, const BalancerOptions& options = {});
std::vector<std::string> balancer_names();

}  // namespace cohort::balance
