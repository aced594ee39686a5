// Test reference (tests/filter/test_float_bound.cpp): the double filter cycle of commit 27d8ca3
// (before issue 37), namespace dualgrid::filter_ref. Not part of the library.
// Private helpers shared by the stage files of DynamicGrid (dynamic_grid.cpp, predict_sort.cpp,
// measurement_grid.cpp, update_cells.cpp, birth.cpp, resample.cpp). Not installed.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include "dualgrid/core/types.hpp"

namespace dualgrid::filter {}  // namespace dualgrid::filter

namespace dualgrid::filter_ref::detail {
using namespace ::dualgrid::filter;

constexpr double kInf = std::numeric_limits<double>::infinity();
// Bits of view_: in a field of view; in front of a detection on its ray; in a bin without returns.
constexpr std::uint8_t kObserved = 1, kFreeRay = 2, kNoReturn = 4;
// Chunks of the counting sort; the sorted order is the same for any chunk count (stable sort).
constexpr int kMaxSortChunks = 8;

inline std::int64_t Mod(std::int64_t a, std::int64_t b) {
  const std::int64_t r = a % b;
  return r < 0 ? r + b : r;
}

// atan2 with |error| < 2.1e-4 rad (measured 2.04e-4): bearing bins are ~1e-2 rad wide, and

// std::exp with the underflow range short-cut: glibc takes a slow path (errno handling) below
// ~-103.97 (float) / ~-745.13 (double), where the correctly rounded result is +0 anyway.
inline float ExpUnder(float x) { return x < -104.0f ? 0.0f : std::exp(x); }
inline double ExpUnder(double x) { return x < -746.0 ? 0.0 : std::exp(x); }

// Prefix sums (resampling, birth allocation) run in fixed blocks of kScanBlock elements, so their
// summation order depends only on the array size.
constexpr std::int64_t kScanBlock = 1 << 14;
// Cells per UpdateCells work item; divides kScanBlock (Birth walks the per-chunk birth lists).
constexpr std::int64_t kCellChunk = 512;
static_assert(kScanBlock % kCellChunk == 0);

// Global index of logical cell (0, 0) of an nx x ny grid of resolution r centred on `centre`
// (DynamicGrid::OriginFor and MeasurementGrid::Build must agree to the cell).
inline std::array<std::int64_t, 2> OriginFor(const Position& centre, double r, int nx, int ny) {
  return {static_cast<std::int64_t>(std::floor(centre.x() / r)) - nx / 2,
          static_cast<std::int64_t>(std::floor(centre.y() / r)) - ny / 2};
}

// static_cast<int64>(std::ceil(x)) for finite |x| < 2^62 (no libm call without SSE4.1).
inline std::int64_t CeilToInt(double x) {
  const std::int64_t i = static_cast<std::int64_t>(x);  // truncation towards zero
  return static_cast<double>(i) < x ? i + 1 : i;
}

}  // namespace dualgrid::filter_ref::detail
