// Cell-level classification scores (not in the paper): predicted free / static / dynamic cells
// against ground-truth boxes rasterised onto the grid.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>

#include <nlohmann/json.hpp>

#include "dualgrid/core/types.hpp"

namespace dualgrid::eval {

/// Cell classes as plain bytes so that per-frame arrays are std::span<const std::uint8_t>.
enum class CellClass : std::uint8_t { kFree = 0, kStatic = 1, kDynamic = 2, kUnknown = 3 };
inline constexpr int kNumTruthClasses = 3;      // free, static, dynamic
inline constexpr int kNumPredictedClasses = 4;  // ... and unknown

/// Predicted class of a cell from its masses: dynamic when p_dynamic > threshold (the paper's
/// rule with 0.6), else static when p_static > threshold, else free when p_free > threshold,
/// else unknown. With threshold >= 0.5 and masses summing to <= 1 at most one class qualifies.
/// Inline: it runs once per cell and mode in every step.
inline CellClass ClassifyCell(double p_free, double p_static, double p_dynamic,
                              double threshold = 0.6) {
  if (p_dynamic > threshold) return CellClass::kDynamic;
  if (p_static > threshold) return CellClass::kStatic;
  if (p_free > threshold) return CellClass::kFree;
  return CellClass::kUnknown;
}

/// ClassifyCell for every cell: out[i] = ClassifyCell(free[i], static_occ[i], dynamic[i],
/// threshold) (as a byte), without branches so that it vectorises (every cell of every mode is
/// classified in each step, cosim::ClassifySnapshot). Throws std::invalid_argument when the sizes
/// differ.
void ClassifyCells(std::span<const float> free, std::span<const float> static_occ,
                   std::span<const float> dynamic, double threshold, std::span<std::uint8_t> out);

/// Ground-truth class per cell: kDynamic when the cell centre lies in a moving box, else kStatic
/// when it lies in a stationary box (parked vehicle, guard-rail segment given as a thin box), else
/// kFree. `cell_centers` and the boxes share a frame. Writes out[i] for every cell.
/// Throws std::invalid_argument on a size mismatch.
void RasterizeTruth(std::span<const Position> cell_centers, std::span<const OrientedBox> moving,
                    std::span<const OrientedBox> stationary, std::span<std::uint8_t> out);

/// A regular grid of square cells [m]: cell (x, y) has its centre at
/// ((origin_ix + x + 0.5) r, (origin_iy + y + 0.5) r), index y * cells_x + x.
struct RegularGrid {
  std::int64_t origin_ix = 0, origin_iy = 0;  ///< global index of cell (0, 0)
  double resolution = 0.0;                    ///< r [m], > 0
  int cells_x = 0, cells_y = 0;
};

/// The same classes as above on a regular grid, O(cells + cells covered by boxes) instead of
/// O(cells x boxes): each box visits only the cells of its bounding rectangle, with its rotation
/// computed once. Cell centres use RegularGrid's formula, and the inside test
/// OrientedBox::Contains's arithmetic, so the result equals the span overload fed with those
/// centres (a property test checks this). Throws std::invalid_argument when out.size() != cells_x *
/// cells_y.
void RasterizeTruth(const RegularGrid& grid, std::span<const OrientedBox> moving,
                    std::span<const OrientedBox> stationary, std::span<std::uint8_t> out);

struct CellMetrics {
  /// confusion[truth][predicted], truth in {free, static, dynamic}, predicted adds unknown.
  std::array<std::array<std::int64_t, kNumPredictedClasses>, kNumTruthClasses> confusion{};
  std::int64_t cells = 0;  ///< (frame, observed cell) pairs counted
  int frames = 0;
  /// Precision / recall / F1 of one class; empty when a denominator is zero.
  std::optional<double> dynamic_precision, dynamic_recall, dynamic_f1;
  std::optional<double> static_precision, static_recall, static_f1;
  /// Share of counted cells whose prediction equals the truth (unknown counts as wrong).
  std::optional<double> accuracy;
};

/// Sums a confusion matrix over frames.
class CellClassificationAccumulator {
 public:
  /// `predicted` and `truth` hold CellClass values per cell; `observed` is empty (all cells count)
  /// or non-zero for cells to count (e.g. cells some radar has observed). Throws
  /// std::invalid_argument on a size mismatch or an out-of-range class.
  void AddFrame(std::span<const std::uint8_t> predicted, std::span<const std::uint8_t> truth,
                std::span<const std::uint8_t> observed = {});

  CellMetrics Result() const;

 private:
  CellMetrics m_;
};

void to_json(nlohmann::json& j, const CellMetrics& m);
void from_json(const nlohmann::json& j, CellMetrics& m);

}  // namespace dualgrid::eval
