// ModeSchedule: which thread filters and scores which mode (cosim/include/.../mode_schedule.hpp).
#include <algorithm>
#include <catch2/catch.hpp>
#include <stdexcept>
#include <vector>

#include "dualgrid/cosim/mode_schedule.hpp"

using dualgrid::cosim::ModeSchedule;

TEST_CASE("ModeSchedule: every mode filtered and scored once, filters fixed per thread",
          "[cosim]") {
  for (int modes = 1; modes <= 9; ++modes) {
    for (int threads = 1; threads <= modes; ++threads) {
      const ModeSchedule s(modes, threads);
      std::vector<int> filtered(modes, 0), scored(modes, 0), filter_thread(modes, -1);
      std::size_t fewest = modes;
      for (int t = 0; t < threads; ++t) {
        fewest = std::min(fewest, s.filters(t).size());
        for (int m : s.filters(t)) {
          ++filtered[m];
          filter_thread[m] = t;
          CHECK(m % threads == t);  // the same thread every step, whatever the step
        }
        CHECK(std::is_sorted(s.filters(t).begin(), s.filters(t).end()));
      }
      for (int t = 0; t < threads; ++t) {
        for (int m : s.scores(t)) {
          ++scored[m];
          // Scored by its own thread, or handed to a thread that filters fewer modes.
          const int own = filter_thread[m];
          CHECK((own == t || s.filters(t).size() < s.filters(own).size()));
        }
      }
      CHECK(std::count(filtered.begin(), filtered.end(), 1) == modes);
      CHECK(std::count(scored.begin(), scored.end(), 1) == modes);
      // The truth is computed after the first filter of a thread with the fewest filters.
      REQUIRE(!s.filters(s.truth_thread()).empty());
      CHECK(s.filters(s.truth_thread()).size() == fewest);
    }
  }
  // Three modes on two threads (the default run on two cores): thread 1 scores mode 0 while
  // thread 0 filters mode 2.
  const ModeSchedule s(3, 2);
  CHECK(s.filters(0) == std::vector<int>{0, 2});
  CHECK(s.filters(1) == std::vector<int>{1});
  CHECK(s.scores(0) == std::vector<int>{2});
  CHECK(s.scores(1) == std::vector<int>{0, 1});
}

TEST_CASE("ModeSchedule: thread counts outside [1, modes] are refused", "[cosim]") {
  CHECK_THROWS_AS(ModeSchedule(3, 0), std::invalid_argument);
  CHECK_THROWS_AS(ModeSchedule(3, 4), std::invalid_argument);
  CHECK_THROWS_AS(ModeSchedule(0, 1), std::invalid_argument);
}
