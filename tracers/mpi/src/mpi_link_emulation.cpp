#include "cohort/tracers/mpi_link_emulation.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

namespace cohort::tracers {

namespace {

// The number at the start of `text` and the rest after it; throws when there is none.
double leading_number(const std::string& whole, const std::string& text, std::string* rest) {
  size_t used = 0;
  double value = 0.0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || !std::isfinite(value) || value < 0.0)
    throw std::invalid_argument("link '" + whole + "': '" + text + "' does not start with a number >= 0");
  *rest = text.substr(used);
  std::transform(rest->begin(), rest->end(), rest->begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return value;
}

}  // namespace

LinkSpec parse_link_spec(const std::string& text) {
  const size_t comma = text.find(',');
  if (comma == std::string::npos)
    throw std::invalid_argument("link '" + text + "': expected RATE,LATENCY such as 10gbit,0.5ms");
  LinkSpec spec;
  spec.text = text;
  std::string unit;
  const double rate = leading_number(text, text.substr(0, comma), &unit);
  double scale = 0.0;
  if (unit == "kbit") scale = 1e3;
  else if (unit == "mbit") scale = 1e6;
  else if (unit == "gbit") scale = 1e9;
  else if (unit == "bit") scale = 1.0;
  else throw std::invalid_argument("link '" + text + "': the rate's unit '" + unit + "' is none of bit, kbit, mbit, gbit");
  spec.bytes_per_second = rate * scale / 8.0;
  if (!(spec.bytes_per_second > 0.0)) throw std::invalid_argument("link '" + text + "': the rate must be above 0");
  const double latency = leading_number(text, text.substr(comma + 1), &unit);
  if (unit == "ms") spec.latency_seconds = latency * 1e-3;
  else if (unit == "us") spec.latency_seconds = latency * 1e-6;
  else if (unit == "s") spec.latency_seconds = latency;
  else throw std::invalid_argument("link '" + text + "': the latency's unit '" + unit + "' is none of s, ms, us");
  return spec;
}

std::optional<LinkSpec> link_spec_from_environment() {
  const char* text = std::getenv("COHORT_MPI_LINK");
  if (!text || !*text) return std::nullopt;
  try {
    return parse_link_spec(text);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("COHORT_MPI_LINK: ") + e.what());
  }
}

MpiClock::time_point LinkSchedule::arrival(int destination, size_t bytes, MpiClock::time_point now) {
  using Seconds = std::chrono::duration<double>;
  MpiClock::time_point& free = free_at_[destination];
  const MpiClock::time_point start = std::max(free, now);
  free = start + std::chrono::duration_cast<MpiClock::duration>(Seconds(double(bytes) / spec_.bytes_per_second));
  return free + std::chrono::duration_cast<MpiClock::duration>(Seconds(spec_.latency_seconds));
}

}  // namespace cohort::tracers
