#include "dualgrid/core/core_split.hpp"

#include <sched.h>

#include <algorithm>
#include <thread>

namespace dualgrid {

int Cores() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof set, &set) == 0 && CPU_COUNT(&set) > 0) return CPU_COUNT(&set);
  return std::max(1u, std::thread::hardware_concurrency());
}

CoreSplit SplitCores(int jobs, int threads, int tasks) {
  CoreSplit s;
  s.cores = Cores();
  s.jobs = jobs > 0 ? jobs : std::max(1, std::min(s.cores, tasks));
  s.threads = threads > 0 ? threads : std::max(1, s.cores / s.jobs);
  return s;
}

std::string CoreSplit::Describe() const {
  std::string out = std::to_string(jobs) + (jobs == 1 ? " process" : " processes") +
                    " at a time x " + std::to_string(threads) +
                    (threads == 1 ? " thread" : " threads") + " on " + std::to_string(cores) +
                    (cores == 1 ? " core" : " cores");
  if (jobs * threads > cores) out += " (oversubscribed as asked: expect slowdowns)";
  return out;
}

}  // namespace dualgrid
