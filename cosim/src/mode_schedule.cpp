#include "dualgrid/cosim/mode_schedule.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>

namespace dualgrid::cosim {

namespace {

constexpr int kMaxSearchedModes = 8;

// The placement of `modes` on `threads` (thread t < modes % threads taking one more) whose largest
// thread cost is smallest; round robin unless something is strictly better, then the first found
// in the search order. Exhaustive: at most kMaxSearchedModes! leaves (40,320), and it runs only
// when the co-simulation re-plans; more modes keep round robin.
std::vector<int> BestPlacement(int modes, int threads, std::span<const double> costs) {
  std::vector<int> capacity(threads, modes / threads);
  for (int t = 0; t < modes % threads; ++t) ++capacity[t];
  std::vector<double> load(threads, 0.0);
  std::vector<int> place(modes), best;
  double best_max = 0.0;
  const std::function<void(int, double)> search = [&](int m, double max_so_far) {
    if (!best.empty() && max_so_far >= best_max) return;  // cannot be strictly better
    if (m == modes) {
      best = place;
      best_max = max_so_far;
      return;
    }
    for (int t = 0; t < threads; ++t) {
      if (capacity[t] == 0) continue;
      const double before = load[t];  // restored exactly: (x + c) - c may differ from x
      --capacity[t];
      load[t] = before + costs[m];
      place[m] = t;
      search(m + 1, std::max(max_so_far, load[t]));
      load[t] = before;
      ++capacity[t];
    }
  };
  // Round robin first: anything else must beat it strictly.
  for (int m = 0; m < modes; ++m) {
    place[m] = m % threads;
    load[m % threads] += costs[m];
  }
  best = place;
  best_max = *std::max_element(load.begin(), load.end());
  if (modes > kMaxSearchedModes) return best;
  std::fill(load.begin(), load.end(), 0.0);
  search(0, 0.0);
  return best;
}

}  // namespace

ModeSchedule::ModeSchedule(int modes, int threads, std::span<const double> costs) {
  if (modes < 1 || threads < 1 || threads > modes)
    throw std::invalid_argument("ModeSchedule: need 1 <= threads <= modes, got " +
                                std::to_string(threads) + " threads for " + std::to_string(modes) +
                                " modes");
  if (!costs.empty() && costs.size() != static_cast<std::size_t>(modes))
    throw std::invalid_argument("ModeSchedule: " + std::to_string(costs.size()) + " costs for " +
                                std::to_string(modes) + " modes");
  for (double c : costs)
    if (!(std::isfinite(c) && c >= 0.0))
      throw std::invalid_argument("ModeSchedule: a cost must be finite and >= 0, got " +
                                  std::to_string(c));
  filters_.resize(threads);
  if (costs.empty()) {
    for (int m = 0; m < modes; ++m) filters_[m % threads].push_back(m);
  } else {
    const std::vector<int> place = BestPlacement(modes, threads, costs);
    for (int m = 0; m < modes; ++m) filters_[place[m]].push_back(m);  // increasing m
  }
}

double ModeSchedule::MaxLoad(std::span<const double> costs) const {
  double max_load = 0.0;
  for (const auto& own : filters_) {
    double load = 0.0;
    for (int m : own) load += costs[static_cast<std::size_t>(m)];
    max_load = std::max(max_load, load);
  }
  return max_load;
}

}  // namespace dualgrid::cosim
