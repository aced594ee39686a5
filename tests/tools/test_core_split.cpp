// How experiment, sweep and regress share the cores (dualgrid/core/core_split.hpp, SplitCores).
#include <catch2/catch.hpp>

#include <sched.h>

#include <string>

#include "dualgrid/core/core_split.hpp"

using dualgrid::Cores;
using dualgrid::SplitCores;

TEST_CASE("Cores counts the CPUs this process may use", "[cores]") {
  cpu_set_t set;
  CPU_ZERO(&set);
  REQUIRE(sched_getaffinity(0, sizeof set, &set) == 0);
  CHECK(Cores() == CPU_COUNT(&set));
}

TEST_CASE("default splits never oversubscribe and use the cores", "[cores]") {
  const int cores = Cores();
  for (int tasks = 1; tasks <= 3 * cores + 1; ++tasks) {
    const auto s = SplitCores(0, 0, tasks);
    CHECK(s.cores == cores);
    CHECK(s.jobs == std::min(cores, tasks));
    CHECK(s.threads >= 1);
    CHECK(s.jobs * s.threads <= cores);
    CHECK(s.jobs * (s.threads + 1) > cores);  // no whole core left idle per process
    CHECK(s.Describe().find("oversubscribed") == std::string::npos);
  }
  // One task gets every core as threads.
  CHECK(SplitCores(0, 0, 1).threads == cores);
}

TEST_CASE("given jobs and threads are kept, and oversubscription is named", "[cores]") {
  const int cores = Cores();
  auto s = SplitCores(3, 0, 10);
  CHECK(s.jobs == 3);
  CHECK(s.threads == std::max(1, cores / 3));
  s = SplitCores(0, 2, 10);
  CHECK(s.threads == 2);
  s = SplitCores(cores + 1, 1, 100);
  CHECK(s.jobs == cores + 1);
  CHECK(s.Describe().find("oversubscribed") != std::string::npos);
  CHECK(SplitCores(2, 1, 5).Describe().rfind("2 processes at a time x 1 thread on ", 0) == 0);
}
