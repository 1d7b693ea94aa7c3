#include <algorithm>
#include <cmath>
#include <numeric>

#include "balancers.h"

namespace cohort::balance {

namespace {

constexpr int kProbeRows[] = {2, 8};  // alternated, so a benched tracer's fit sees two band sizes

// The time every taker finishes at when `takers` share `total_work`: sum_i (T - F_i) / c_i = W.
double finish_time(const std::vector<bool>& takers, const std::vector<double>& fixed, const std::vector<double>& cost,
                   double total_work) {
  double rate = 0.0, offset = 0.0;
  for (size_t i = 0; i < takers.size(); ++i) {
    if (!takers[i]) continue;
    rate += 1.0 / cost[i];
    offset += fixed[i] / cost[i];
  }
  return rate > 0.0 ? (total_work + offset) / rate : INFINITY;
}

}  // namespace

std::vector<double> WholeCostBalancer::work_prefix(const DivideInput& in, bool& from_proxy) const {
  const size_t rows = static_cast<size_t>(in.rows);
  std::vector<double> prefix(rows + 1, 0.0);
  from_proxy = in.row_cost_proxy.size() == rows;
  double total = 0.0;
  if (from_proxy) {
    for (float v : in.row_cost_proxy) total += std::isfinite(v) && v > 0.0f ? v : 0.0;
    from_proxy = total > 0.0;
  }
  // As Row Cost's map: a row the proxy calls free still costs a little (rays are traced).
  const double floor = from_proxy ? 0.05 * total / static_cast<double>(rows) : 0.0;
  for (size_t r = 0; r < rows; ++r) {
    const double v = from_proxy ? in.row_cost_proxy[r] : 1.0;
    prefix[r + 1] = prefix[r] + (from_proxy ? std::max(std::isfinite(v) ? v : 0.0, floor) : 1.0);
  }
  return prefix;
}

std::vector<bool> WholeCostBalancer::choose_takers(const std::vector<double>& fixed, const std::vector<double>& cost,
                                                   double total_work) const {
  const size_t count = fixed.size();
  std::vector<bool> takers(count, true);
  auto taking = [&] { return static_cast<size_t>(std::count(takers.begin(), takers.end(), true)); };
  // A tracer whose fixed cost alone outlasts the others' frame can only slow it: bench the worst such
  // one and look again, until every taker starts its rows before the frame would end.
  for (;;) {
    const double t = finish_time(takers, fixed, cost, total_work);
    size_t worst = count;
    for (size_t i = 0; i < count; ++i)
      if (takers[i] && fixed[i] >= t && (worst == count || fixed[i] > fixed[worst])) worst = i;
    if (worst == count || taking() <= 1) break;
    takers[worst] = false;
  }
  // Then bench the taker that helps least while it helps less than min_gain.
  while (taking() > 1) {
    const double t = finish_time(takers, fixed, cost, total_work);
    size_t least = count;
    double least_gain = 0.0;
    for (size_t i = 0; i < count; ++i) {
      if (!takers[i]) continue;
      takers[i] = false;
      const double without = finish_time(takers, fixed, cost, total_work);
      takers[i] = true;
      const double gain = (without - t) / without;
      if (least == count || gain < least_gain) {
        least = i;
        least_gain = gain;
      }
    }
    if (least_gain >= options_.min_gain) break;
    takers[least] = false;
  }
  return takers;
}

std::vector<Band> WholeCostBalancer::cut(const std::vector<double>& prefix, const std::vector<double>& shares, int rows) const {
  const size_t count = shares.size();
  const double total_share = std::accumulate(shares.begin(), shares.end(), 0.0);
  const double total_work = prefix.back();
  // Fractional row where the running work reaches each band's end.
  std::vector<double> position(count);
  double running = 0.0;
  for (size_t i = 0; i < count; ++i) {
    running += shares[i];
    const double target = total_work * running / total_share;
    const size_t r = static_cast<size_t>(std::upper_bound(prefix.begin(), prefix.end(), target) - prefix.begin());
    if (r == 0) position[i] = 0.0;
    else if (r >= prefix.size()) position[i] = rows;
    else position[i] = static_cast<double>(r - 1) + (target - prefix[r - 1]) / std::max(prefix[r] - prefix[r - 1], 1e-12);
  }
  // Cuts on a grid of `step` rows; with fine cuts, a cut next to a small band falls on any row and
  // others on the paper's units. Takers keep a grid step at least, the benched get nothing.
  const int step = options_.fine_cuts ? 1 : kRowsPerUnit;
  const int grid = (rows + step - 1) / step;
  std::vector<int> takers_after(count, 0);
  for (size_t i = count; i-- > 1;) takers_after[i - 1] = takers_after[i] + (shares[i] > 0.0);
  std::vector<Band> bands(count);
  int previous = 0;
  double previous_position = 0.0;
  for (size_t i = 0; i < count; ++i) {
    const bool taker = shares[i] > 0.0;
    int at = previous;
    if (taker) {
      const double here = position[i] - previous_position;
      const double next = i + 1 < count ? position[i + 1] - position[i] : 0.0;
      const bool small = here < options_.fine_below_rows || (i + 1 < count && shares[i + 1] > 0.0 && next < options_.fine_below_rows);
      const int unit = step == 1 && !small ? kRowsPerUnit : 1;  // in grid steps
      at = static_cast<int>(std::lround(position[i] / (step * unit))) * unit;
      at = std::min(std::max(at, previous + 1), std::max(grid - takers_after[i], previous + 1));
      at = std::min(at, grid);
      if (takers_after[i] == 0) at = grid;
    }
    if (i + 1 == count) at = grid;
    bands[i] = Band{std::min(previous * step, rows), std::min(at * step, rows)};
    previous = at;
    previous_position = position[i];
  }
  return bands;
}

std::vector<Band> WholeCostBalancer::divide(const DivideInput& in) {
  const size_t count = in.tracers.size();
  probes_.assign(count, Band{});
  if (count == 0) return {};
  if (in.rows <= 0) return std::vector<Band>(count);
  restarted_for_new_height(*this, rows_, in.rows);
  probes_.assign(count, Band{});
  // Work is in the proxy's units or in rows; times learnt in one mean nothing in the other.
  bool from_proxy = false;
  const std::vector<double> prefix = work_prefix(in, from_proxy);
  if (from_proxy != proxy_mode_) {
    fits_.clear();
    proxy_mode_ = from_proxy;
  }
  // The per-work cost follows each band like Perfect Smooth without a proxy (what a row costs moves
  // with the view); with one, the proxy carries the view and the cost is a hardware property.
  const double follow = proxy_mode_ ? options_.speed_rate : options_.alpha;
  for (const TracerMeasurement& m : in.previous) {
    if (!(m.ms > 0.0) || !std::isfinite(m.ms)) continue;
    const int begin = std::clamp(m.band.begin, 0, in.rows), end = std::clamp(m.band.end, begin, in.rows);
    if (end <= begin) continue;
    fits_.try_emplace(m.tracer, follow).first->second.add(prefix[static_cast<size_t>(end)] - prefix[static_cast<size_t>(begin)], m.ms);
  }

  // Predictions for this frame's tracers; one never measured is taken as average with no fixed cost.
  std::vector<double> fixed(count, 0.0), cost(count, 0.0);
  double known_cost = 0.0;
  int known = 0;
  for (size_t i = 0; i < count; ++i) {
    auto it = fits_.find(in.tracers[i]);
    if (it == fits_.end() || !it->second.known()) continue;
    fixed[i] = it->second.fixed_ms();
    cost[i] = it->second.ms_per_work();
    known_cost += cost[i];
    ++known;
  }
  for (size_t i = 0; i < count; ++i)
    if (!(cost[i] > 0.0)) cost[i] = known > 0 ? known_cost / known : 1.0;

  const double total_work = prefix.back();
  const std::vector<bool> takers = choose_takers(fixed, cost, total_work);
  const double finish = finish_time(takers, fixed, cost, total_work);
  std::vector<double> shares(count, 0.0);
  for (size_t i = 0; i < count; ++i) {
    if (takers[i]) shares[i] = std::max((finish - fixed[i]) / cost[i], 1e-9 * total_work);
  }

  // Benched tracers are probed now and then, off the frame's critical path.
  for (size_t i = 0; i < count; ++i) {
    const int id = in.tracers[i];
    if (takers[i]) {
      benched_.erase(id);
      continue;
    }
    Benched& b = benched_[id];
    if (++b.frames < options_.probe_interval) continue;
    b.frames = 0;
    const int size = std::min(kProbeRows[b.probes++ % 2], in.rows);
    const int begin = std::clamp(in.rows / 2 - size / 2, 0, in.rows - size);
    probes_[i] = Band{begin, begin + size};
  }
  return cut(prefix, shares, in.rows);
}

}  // namespace cohort::balance
