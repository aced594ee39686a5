// Bounds shared by every entry point (the command line, scenario files, the Python module), so
// that each refuses exactly what the others refuse.
#pragma once

#include <cstdint>

#include "dualgrid/core/core_split.hpp"

namespace dualgrid {

/// Largest seed accepted anywhere: 2^53 - 1, so that a seed written to JSON is read back exactly
/// by readers that hold numbers as doubles (Python's json, JavaScript).
inline constexpr std::uint64_t kMaxSeed = (std::uint64_t{1} << 53) - 1;

/// OpenMP threads (and parallel runs) per core at most: more only adds switching, and very large
/// counts exhaust the stack space of the thread pool.
inline constexpr int kMaxThreadsPerCore = 4;

/// The most OpenMP threads a run may ask for: kMaxThreadsPerCore x Cores().
inline int MaxThreads() { return kMaxThreadsPerCore * Cores(); }

/// The share of the machine's physical memory one configuration may plan to use: more is refused
/// at once rather than left to the kernel's out-of-memory killer, which would take the process
/// (or the Python interpreter) with everything already computed.
inline constexpr double kMaxMemoryShare = 0.8;

/// This machine's physical memory [bytes] (sysconf), 0 when it cannot be read.
double PhysicalMemoryBytes();

}  // namespace dualgrid
