// ModeSchedule: which thread filters which mode (cosim/include/.../mode_schedule.hpp).
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "dualgrid/cosim/mode_schedule.hpp"

using dualgrid::cosim::ModeSchedule;

namespace {

// What every schedule guarantees: each mode filtered once, in increasing mode order per thread,
// threads t < modes % threads filtering one more than the others.
void CheckInvariants(const ModeSchedule& s, int modes, int threads) {
  std::vector<int> filtered(modes, 0);
  for (int t = 0; t < threads; ++t) {
    for (int m : s.filters(t)) ++filtered[m];
    CHECK(std::is_sorted(s.filters(t).begin(), s.filters(t).end()));
    CHECK(static_cast<int>(s.filters(t).size()) == modes / threads + (t < modes % threads ? 1 : 0));
  }
  CHECK(std::count(filtered.begin(), filtered.end(), 1) == modes);
}

}  // namespace

TEST_CASE("ModeSchedule: every mode filtered and scored once, filters fixed per thread",
          "[cosim]") {
  for (int modes = 1; modes <= 9; ++modes) {
    for (int threads = 1; threads <= modes; ++threads) {
      const ModeSchedule s(modes, threads);
      CheckInvariants(s, modes, threads);
      for (int t = 0; t < threads; ++t)
        for (int m : s.filters(t)) CHECK(m % threads == t);  // round robin without costs
    }
  }
  // Three modes on two threads (the default run on two cores).
  const ModeSchedule s(3, 2);
  CHECK(s.filters(0) == std::vector<int>{0, 2});
  CHECK(s.filters(1) == std::vector<int>{1});
}

TEST_CASE("ModeSchedule: thread counts outside [1, modes] are refused", "[cosim]") {
  CHECK_THROWS_AS(ModeSchedule(3, 0), std::invalid_argument);
  CHECK_THROWS_AS(ModeSchedule(3, 4), std::invalid_argument);
  CHECK_THROWS_AS(ModeSchedule(0, 1), std::invalid_argument);
}

namespace {

// The smallest largest thread load over every placement with ModeSchedule's filter counts
// (threads t < modes % threads take one more): the reference, by enumerating placements.
double BestMaxLoad(int modes, int threads, const std::vector<double>& costs) {
  std::vector<int> place(modes, 0);
  double best = 1e300;
  while (true) {
    std::vector<int> count(threads, 0);
    std::vector<double> load(threads, 0.0);
    for (int m = 0; m < modes; ++m) {
      ++count[place[m]];
      load[place[m]] += costs[m];
    }
    bool valid = true;
    for (int t = 0; t < threads; ++t)
      valid = valid && count[t] == modes / threads + (t < modes % threads ? 1 : 0);
    if (valid) best = std::min(best, *std::max_element(load.begin(), load.end()));
    int m = 0;  // next placement (odometer)
    while (m < modes && ++place[m] == threads) place[m++] = 0;
    if (m == modes) return best;
  }
}

}  // namespace

TEST_CASE("ModeSchedule with costs: the smallest largest load, round robin unless strictly better",
          "[cosim]") {
  std::uint64_t state = 12345;  // a small LCG: costs in [0.5, 1.5) s
  const auto cost = [&] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return 0.5 + static_cast<double>(state >> 11) / 9007199254740992.0;
  };
  for (int modes = 1; modes <= 7; ++modes) {
    for (int threads = 1; threads <= modes; ++threads) {
      for (int draw = 0; draw < 5; ++draw) {
        std::vector<double> costs(modes);
        for (double& c : costs) c = cost();
        const ModeSchedule s(modes, threads, costs);
        INFO(modes << " modes, " << threads << " threads, draw " << draw);
        CHECK(s.MaxLoad(costs) == BestMaxLoad(modes, threads, costs));
        CheckInvariants(s, modes, threads);
      }
      // Equal costs: nothing beats round robin strictly, so it stays.
      CHECK(ModeSchedule(modes, threads, std::vector<double>(modes, 1.0)) ==
            ModeSchedule(modes, threads));
    }
  }
  // A tie that only rounding would break: {0, 3} / {1, 2} has the same largest sum as round
  // robin's {0, 2} / {1, 3} (0.6 + 0.6 = 1.2), but a search that adds and then subtracts the
  // costs reaches it with a load of 1.1999999999999997 and would leave round robin.
  const std::vector<double> tie = {0.6, 0.6, 0.3, 0.6};
  CHECK(ModeSchedule(4, 2, tie) == ModeSchedule(4, 2));
  // The recorded three-mode loop's per-cycle times [ms] by the schedule's own timers (position,
  // velocity, dual; docs/performance.md round 5): position and velocity together, dual alone.
  const ModeSchedule s(3, 2, std::vector<double>{0.932, 0.839, 0.963});
  CHECK(s.filters(0) == std::vector<int>{0, 1});
  CHECK(s.filters(1) == std::vector<int>{2});
  CHECK_THROWS_AS(ModeSchedule(3, 2, std::vector<double>{1.0, 1.0}), std::invalid_argument);
  CHECK_THROWS_AS(ModeSchedule(3, 2, std::vector<double>{1.0, -1.0, 1.0}), std::invalid_argument);
  CHECK_THROWS_AS(ModeSchedule(3, 2, std::vector<double>{1.0, NAN, 1.0}), std::invalid_argument);
}
