#include "dualgrid/cosim/mode_schedule.hpp"

#include <stdexcept>
#include <string>

namespace dualgrid::cosim {

ModeSchedule::ModeSchedule(int modes, int threads) {
  if (modes < 1 || threads < 1 || threads > modes)
    throw std::invalid_argument("ModeSchedule: need 1 <= threads <= modes, got " +
                                std::to_string(threads) + " threads for " + std::to_string(modes) +
                                " modes");
  filters_.resize(threads);
  scores_.resize(threads);
  for (int m = 0; m < modes; ++m) filters_[m % threads].push_back(m);
  // Threads t < extra filter one mode more than the others; thread threads-1-t, if it is one with
  // fewer, scores that thread's first mode (ready earliest) while t filters its next.
  const int extra = modes % threads;
  for (int t = 0; t < threads; ++t) {
    const auto& own = filters_[t];
    const int helper = threads - 1 - t;
    for (std::size_t k = 0; k < own.size(); ++k) {
      const bool handed_over = t < extra && helper >= extra && k == 0;
      scores_[handed_over ? helper : t].push_back(own[k]);
    }
  }
}

}  // namespace dualgrid::cosim
