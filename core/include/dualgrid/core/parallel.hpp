// Parallel loops that cost nothing when they would run on one thread anyway.
//
// An OpenMP region that gets one thread still builds a team and runs its barriers (a few
// microseconds each; measured in docs/performance.md). ParallelFor runs the loop plainly when it
// would get one thread. Compiled without OpenMP (_OPENMP undefined) every loop is plain.
#pragma once

#include <cstdint>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace dualgrid {

/// True when a parallel region opened here would get one thread: one thread is allowed, or the
/// caller is inside a region and no further level may be active (omp_get_max_active_levels).
inline bool OneThreadHere() {
#ifdef _OPENMP
  return omp_get_max_threads() == 1 || omp_get_active_level() >= omp_get_max_active_levels();
#else
  return true;
#endif
}

/// How ParallelFor deals out iterations: kStatic = schedule(static) (contiguous ranges),
/// kRoundRobin = schedule(static, 1) (the same index on the same thread every call),
/// kDynamic = schedule(dynamic, chunk).
enum class Schedule { kStatic, kRoundRobin, kDynamic };

/// body(i) for i in [0, n): in a parallel loop, or plainly (in order) when OneThreadHere() or
/// !worth (too little work to share). Results must not depend on which thread runs which i
/// (every caller computes each i from the same inputs). `chunk` >= 1 is used by kDynamic only.
template <typename Body>
void ParallelFor(std::int64_t n, Schedule schedule, Body&& body, bool worth = true,
                 std::int64_t chunk = 1) {
  if (!worth || OneThreadHere()) {
    for (std::int64_t i = 0; i < n; ++i) body(i);
    return;
  }
  switch (schedule) {
    case Schedule::kStatic:
#pragma omp parallel for schedule(static)
      for (std::int64_t i = 0; i < n; ++i) body(i);
      break;
    case Schedule::kRoundRobin:
#pragma omp parallel for schedule(static, 1)
      for (std::int64_t i = 0; i < n; ++i) body(i);
      break;
    case Schedule::kDynamic:
#pragma omp parallel for schedule(dynamic, chunk)
      for (std::int64_t i = 0; i < n; ++i) body(i);
      break;
  }
}

}  // namespace dualgrid
