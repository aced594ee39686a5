// The threads that run one DynamicGrid cycle (internal): the team of the one OpenMP parallel
// region that DynamicGrid::Update (and Reframe) opens per call, or the calling thread alone with
// no region at all (docs/algorithm.md, "One cycle": threads).
//
// Contract: a Team with `shared` set is used only inside that region, by every thread of it, and
// every thread reaches the same helpers below in the same order (they are worksharing constructs
// and barriers of that region). A Team without `shared` runs every helper as a plain loop on the
// calling thread and contains no OpenMP construct, so nothing binds to a region the caller may be
// inside (the co-simulation calls Update from its own per-mode threads). No helper may throw:
// an exception cannot leave a parallel region, so the cycle allocates before it opens one.
#pragma once

#include <cstdint>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace dualgrid::filter::detail {

struct Team {
  bool shared = false;  ///< inside the cycle's own region with more than one thread
  int id = 0;           ///< this thread's number in the team, 0 .. size - 1
  int size = 1;

  /// The calling thread alone (no region).
  static Team Solo() { return {}; }
  /// The encountering thread of the enclosing region, which must be the cycle's own.
  static Team OfRegion() {
#ifdef _OPENMP
    const int n = omp_get_num_threads();
    return {n > 1, omp_get_thread_num(), n};
#else
    return {};
#endif
  }
};

/// body(i) for i in [0, n): schedule(static) (contiguous ranges), then a barrier.
template <typename Body>
void ForStatic(const Team& t, std::int64_t n, Body&& body) {
  if (!t.shared) {
    for (std::int64_t i = 0; i < n; ++i) body(i);
    return;
  }
#pragma omp for schedule(static)
  for (std::int64_t i = 0; i < n; ++i) body(i);
}

/// body(i) for i in [0, n): schedule(static, 1) (index i on thread i mod size, the same thread
/// every cycle), then a barrier.
template <typename Body>
void ForRoundRobin(const Team& t, std::int64_t n, Body&& body) {
  if (!t.shared) {
    for (std::int64_t i = 0; i < n; ++i) body(i);
    return;
  }
#pragma omp for schedule(static, 1)
  for (std::int64_t i = 0; i < n; ++i) body(i);
}

/// Every thread waits here for the others.
inline void Barrier(const Team& t) {
  if (!t.shared) return;
#pragma omp barrier
}

/// body(i) for i in [0, n): schedule(dynamic, chunk), without a barrier: a thread that runs out
/// of iterations goes on at once (the caller orders any reader of the results behind a later
/// barrier).
template <typename Body>
void ForDynamicNoWait(const Team& t, std::int64_t n, Body&& body, std::int64_t chunk = 1) {
  if (!t.shared) {
    for (std::int64_t i = 0; i < n; ++i) body(i);
    return;
  }
#pragma omp for schedule(dynamic, chunk) nowait
  for (std::int64_t i = 0; i < n; ++i) body(i);
}

/// ForDynamicNoWait, then a barrier.
template <typename Body>
void ForDynamic(const Team& t, std::int64_t n, Body&& body, std::int64_t chunk = 1) {
  ForDynamicNoWait(t, n, body, chunk);
  Barrier(t);
}

/// f() on one thread, then a barrier.
template <typename F>
void Single(const Team& t, F&& f) {
  if (!t.shared) {
    f();
    return;
  }
#pragma omp single
  f();
}

/// f() on one thread; the others go on at once (no barrier).
template <typename F>
void SingleNoWait(const Team& t, F&& f) {
  if (!t.shared) {
    f();
    return;
  }
#pragma omp single nowait
  f();
}

/// f() and g() on two threads at once when the team has them (f then g otherwise), then a
/// barrier.
template <typename F, typename G>
void Both(const Team& t, F&& f, G&& g) {
  if (!t.shared) {
    f();
    g();
    return;
  }
#pragma omp sections
  {
#pragma omp section
    f();
#pragma omp section
    g();
  }
}

}  // namespace dualgrid::filter::detail
