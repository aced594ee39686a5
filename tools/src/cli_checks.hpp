// Command-line value checks with readable messages ("--seeds: expected a whole number in
// [1, 10000], got '0'") in place of CLI11's generic range text, and the bounds they enforce.
#pragma once

#include <cstdint>
#include <string>

#include <CLI/CLI.hpp>

#include "dualgrid/core/core_split.hpp"
#include "dualgrid/core/limits.hpp"
#include "dualgrid/sim/scenario.hpp"

namespace dualgrid::tools {

/// Largest seed accepted anywhere (core/limits.hpp).
using dualgrid::kMaxSeed;
/// At most this many seeds per experiment (each is one process and one folder).
inline constexpr int kMaxSeeds = 10000;
/// OpenMP threads per core at most (core/limits.hpp).
using dualgrid::kMaxThreadsPerCore;
/// Longest simulated duration [s] accepted on the command line (as in a scenario file).
inline constexpr double kMaxDuration = sim::kMaxDuration;

/// A whole number in [lo, hi] (no sign for lo >= 0, no fraction, no trailing text).
CLI::Validator WholeNumber(long long lo, long long hi);
/// A non-empty path (an empty --out would write into the working folder).
CLI::Validator NonEmptyPath();
/// KEY=VALUE with a non-empty KEY (`--set`).
CLI::Validator OverrideSpec();
/// A finite number in (lo, hi] when lo_open, else [lo, hi].
CLI::Validator Number(double lo, double hi, bool lo_open);

}  // namespace dualgrid::tools
