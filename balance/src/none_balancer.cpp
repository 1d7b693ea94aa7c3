#include "balancers.h"

namespace cohort::balance {

std::vector<Band> NoneBalancer::divide(const DivideInput& in) {
  return equal_bands(in.rows, static_cast<int>(in.tracers.size()));
}

}  // namespace cohort::balance
