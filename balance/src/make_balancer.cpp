#include <stdexcept>

#include "balancers.h"

namespace cohort::balance {

std::vector<std::string> balancer_names() { return {"none", "robin-hood", "perfect", "perfect-smooth", "row-cost"}; }

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
  std::string known;
  for (const std::string& n : balancer_names()) known += (known.empty() ? "" : ", ") + n;
  throw std::invalid_argument("unknown balancer '" + std::string(name) + "' (known: " + known + ")");
}

}  // namespace cohort::balance
