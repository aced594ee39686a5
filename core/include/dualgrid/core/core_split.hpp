// How parallel runs share the machine's cores: the CPUs this process may use, and the split of
// them into child processes x OpenMP threads (used by experiment, sweep and regress).
#pragma once

#include <string>

namespace dualgrid {

/// The CPUs this process may run on (taskset, a Slurm allocation's cpuset), at least 1.
int Cores();

/// How parallel runs share the cores: `jobs` child processes at a time, each with `threads` OpenMP
/// threads. Given values (> 0) are kept; by default jobs = min(cores, tasks) and
/// threads = cores / jobs, so that jobs x threads <= cores (spinning or oversubscribed OpenMP
/// teams slow every run by an order of magnitude on a shared machine: docs/performance.md).
struct CoreSplit {
  int jobs = 1, threads = 1, cores = 1;
  /// "2 processes at a time x 1 thread on 2 cores", flagged when jobs x threads > cores.
  std::string Describe() const;
};
CoreSplit SplitCores(int jobs, int threads, int tasks);

}  // namespace dualgrid
