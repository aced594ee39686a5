// Point-level dynamic classification (docs/recorded-data.md, "Scores without boxes"): recorded
// data label every detection, not boxes, so the grid is scored at the labelled points. A point of
// a moving labelled object inside a dynamic cell is a true positive, a static point inside a
// dynamic cell a false positive; a moving point outside dynamic cells a false negative.
#pragma once

#include <cstdint>
#include <optional>

#include <nlohmann/json.hpp>

namespace dualgrid::eval {

struct PointMetrics {
  std::int64_t true_positives = 0;   ///< moving points in dynamic cells
  std::int64_t false_positives = 0;  ///< static points in dynamic cells
  std::int64_t false_negatives = 0;  ///< moving points in cells that are not dynamic
  std::int64_t true_negatives = 0;   ///< static points in cells that are not dynamic
  std::int64_t outside = 0;          ///< labelled points outside the grid (not counted above)
  int frames = 0;
  /// Empty when a denominator is zero.
  std::optional<double> precision, recall, f1;
};

/// Sums PointMetrics over frames.
class PointClassificationAccumulator {
 public:
  /// One labelled point: `moving` (a moving road user's label) or static; `in_grid` false for a
  /// point outside the grid; `dynamic` its cell's P(dynamic) above the threshold.
  void Add(bool moving, bool in_grid, bool dynamic) {
    if (!in_grid) {
      ++m_.outside;
      return;
    }
    if (moving) {
      ++(dynamic ? m_.true_positives : m_.false_negatives);
    } else {
      ++(dynamic ? m_.false_positives : m_.true_negatives);
    }
  }
  void EndFrame() { ++m_.frames; }
  PointMetrics Result() const;

 private:
  PointMetrics m_;
};

void to_json(nlohmann::json& j, const PointMetrics& m);
void from_json(const nlohmann::json& j, PointMetrics& m);

}  // namespace dualgrid::eval
