#include <stdexcept>

#include "balancers.h"
#include "sit_out_trials.h"

namespace cohort::balance {

std::vector<std::string> balancer_names() { return {"none", "robin-hood", "perfect", "perfect-smooth", "row-cost", "whole-cost"}; }

std::unique_ptr<Balancer> make_balancer(std::string_view name, const BalancerOptions& options) {
  if (name == "none") return std::make_unique<NoneBalancer>();
  if (name == "robin-hood") return std::make_unique<RobinHoodBalancer>(options.robin_hood_units);
  if (name == "perfect") return std::make_unique<PerfectBalancer>(1.0, false);
  if (name == "perfect-smooth") {
    if (!(options.alpha > 0.0 && options.alpha <= 1.0)) throw std::invalid_argument("perfect-smooth: alpha must be in (0, 1]");
    return std::make_unique<PerfectBalancer>(options.alpha, true);
  }
  if (name == "row-cost") {
    if (!(options.cost_rate > 0.0 && options.cost_rate <= 1.0) || !(options.speed_rate > 0.0 && options.speed_rate <= 1.0))
      throw std::invalid_argument("row-cost: cost_rate and speed_rate must be in (0, 1]");
    return std::make_unique<RowCostBalancer>(options.cost_rate, options.speed_rate);
  }
  if (name == "whole-cost") {
    if (!(options.alpha > 0.0 && options.alpha <= 1.0) || !(options.speed_rate > 0.0 && options.speed_rate <= 1.0))
      throw std::invalid_argument("whole-cost: alpha and speed_rate must be in (0, 1]");
    if (!(options.min_gain >= 0.0 && options.min_gain < 1.0)) throw std::invalid_argument("whole-cost: min_gain must be in [0, 1)");
    if (options.probe_interval < 1) throw std::invalid_argument("whole-cost: probe_interval must be >= 1");
    if (options.fine_below_rows < 0) throw std::invalid_argument("whole-cost: fine_below_rows must be >= 0");
    if (!options.frame_trials) return std::make_unique<WholeCostBalancer>(options);
    if (!(options.trial_share > 0.0 && options.trial_share < 1.0) || options.trial_window < 2 ||
        options.trial_settle < 0 || options.trial_settle >= options.trial_window || options.trial_pairs < 1 ||
        !(options.trial_min_gain >= 0.0 && options.trial_min_gain < 1.0) || options.trial_warmup < 0 ||
        options.trial_every < 1)
      throw std::invalid_argument("whole-cost: sit-out trial options out of range (share in (0, 1), window >= 2, "
                                  "0 <= settle < window, pairs >= 1, min_gain in [0, 1), warmup >= 0, every >= 1)");
    return std::make_unique<SitOutTrials>(std::make_unique<WholeCostBalancer>(options), options);
  }
  std::string known;
  for (const std::string& n : balancer_names()) known += (known.empty() ? "" : ", ") + n;
  throw std::invalid_argument("unknown balancer '" + std::string(name) + "' (known: " + known + ")");
}

}  // namespace cohort::balance
