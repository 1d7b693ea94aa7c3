#include <stdexcept>

#include "balance_bench.h"

namespace cohort::app {

void write_balance_plot(const std::string& file, const std::vector<BalanceBenchRun>& runs) {
  (void)runs;
  throw std::runtime_error("--plot " + file + ": the chart writer is not built yet");
}

}  // namespace cohort::app
