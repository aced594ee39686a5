#include "dualgrid/eval/cell_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

#include "json_util.hpp"

namespace dualgrid::eval {

using detail::OptFromJson;
using detail::OptToJson;

void RasterizeTruth(std::span<const Position> cell_centers, std::span<const OrientedBox> moving,
                    std::span<const OrientedBox> stationary, std::span<std::uint8_t> out) {
  if (out.size() != cell_centers.size())
    throw std::invalid_argument("RasterizeTruth: " + std::to_string(out.size()) + " outputs for " +
                                std::to_string(cell_centers.size()) + " cells");
  const auto n = static_cast<std::int64_t>(cell_centers.size());
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < n; ++i) {
    auto c = CellClass::kFree;
    for (const OrientedBox& b : stationary) {
      if (b.Contains(cell_centers[i])) c = CellClass::kStatic;
    }
    for (const OrientedBox& b : moving) {
      if (b.Contains(cell_centers[i])) c = CellClass::kDynamic;
    }
    out[i] = static_cast<std::uint8_t>(c);
  }
}

namespace {

// Marks with `value` every cell of `grid` whose centre lies in `b` (BoxTest: Contains's test with
// the rotation hoisted out of the cell loop).
void StampBox(const RegularGrid& grid, const OrientedBox& b, std::uint8_t value,
              std::span<std::uint8_t> out) {
  // A non-finite box contains no centre (the comparisons below would all be false).
  if (!b.center.allFinite() || !std::isfinite(b.yaw) || !std::isfinite(b.length) ||
      !std::isfinite(b.width))
    return;
  const BoxTest box(b);
  double lo_x = b.center.x(), hi_x = lo_x, lo_y = b.center.y(), hi_y = lo_y;
  for (const Position& c : b.Corners()) {
    lo_x = std::min(lo_x, c.x());
    hi_x = std::max(hi_x, c.x());
    lo_y = std::min(lo_y, c.y());
    hi_y = std::max(hi_y, c.y());
  }
  const double r = grid.resolution;
  // One cell of margin on each side: the exact test below decides, rounding cannot drop a cell.
  auto first = [&](double lo, std::int64_t origin) {
    return std::max<std::int64_t>(0, static_cast<std::int64_t>(std::floor(lo / r)) - origin - 1);
  };
  auto last = [&](double hi, std::int64_t origin, int n) {
    return std::min<std::int64_t>(n - 1,
                                  static_cast<std::int64_t>(std::floor(hi / r)) - origin + 1);
  };
  const std::int64_t x0 = first(lo_x, grid.origin_ix),
                     x1 = last(hi_x, grid.origin_ix, grid.cells_x);
  const std::int64_t y0 = first(lo_y, grid.origin_iy),
                     y1 = last(hi_y, grid.origin_iy, grid.cells_y);
  for (std::int64_t y = y0; y <= y1; ++y) {
    const double cy = (static_cast<double>(grid.origin_iy + y) + 0.5) * r;
    for (std::int64_t x = x0; x <= x1; ++x) {
      if (box.Contains({(static_cast<double>(grid.origin_ix + x) + 0.5) * r, cy}))
        out[static_cast<std::size_t>(y) * static_cast<std::size_t>(grid.cells_x) +
            static_cast<std::size_t>(x)] = value;
    }
  }
}

}  // namespace

void RasterizeTruth(const RegularGrid& grid, std::span<const OrientedBox> moving,
                    std::span<const OrientedBox> stationary, std::span<std::uint8_t> out) {
  const std::size_t n =
      static_cast<std::size_t>(std::max(grid.cells_x, 0)) * std::max(grid.cells_y, 0);
  if (out.size() != n)
    throw std::invalid_argument("RasterizeTruth: " + std::to_string(out.size()) + " outputs for " +
                                std::to_string(n) + " cells");
  std::fill(out.begin(), out.end(), static_cast<std::uint8_t>(CellClass::kFree));
  // Stationary first, moving over it: the span overload's precedence.
  for (const OrientedBox& b : stationary)
    StampBox(grid, b, static_cast<std::uint8_t>(CellClass::kStatic), out);
  for (const OrientedBox& b : moving)
    StampBox(grid, b, static_cast<std::uint8_t>(CellClass::kDynamic), out);
}

void ClassifyCells(std::span<const float> free, std::span<const float> static_occ,
                   std::span<const float> dynamic, double threshold, std::span<std::uint8_t> out) {
  const std::size_t n = out.size();
  if (free.size() != n || static_occ.size() != n || dynamic.size() != n)
    throw std::invalid_argument("ClassifyCells: sizes differ (" + std::to_string(free.size()) +
                                " free, " + std::to_string(static_occ.size()) + " static, " +
                                std::to_string(dynamic.size()) + " dynamic, " + std::to_string(n) +
                                " out)");
  static_assert(
      static_cast<int>(CellClass::kFree) == 0 && static_cast<int>(CellClass::kStatic) == 1 &&
      static_cast<int>(CellClass::kDynamic) == 2 && static_cast<int>(CellClass::kUnknown) == 3);
  // ClassifyCell's cascade as arithmetic on its three tests (each false for NaN, as there): not
  // dynamic, not static, not free -> 3; the first test that holds wins.
  // The threshold as the float t with (x > t) == (x > threshold) for every float x (the largest
  // float not above it), so that the comparisons stay in float and vectorise.
  float t = static_cast<float>(threshold);
  if (static_cast<double>(t) > threshold)
    t = std::nextafter(t, -std::numeric_limits<float>::infinity());
  for (std::size_t i = 0; i < n; ++i) {
    const int d = dynamic[i] > t, s = static_occ[i] > t, f = free[i] > t;
    const int rest = s + (1 - s) * 3 * (1 - f);  // static 1, else free 0, else unknown 3
    out[i] = static_cast<std::uint8_t>(2 * d + (1 - d) * rest);
  }
}

namespace {

using Bytes = std::uint8_t __attribute__((vector_size(16)));
constexpr int kCodes = kNumTruthClasses * kNumPredictedClasses;  // code = 4 truth + predicted
using Confusion = std::array<std::array<std::int64_t, kNumPredictedClasses>, kNumTruthClasses>;

// Counts the cells [0, end) (end a multiple of 16) into `frame`, 16 cells per step on byte lanes:
// each cell's code (4 truth + predicted, or 15 when not observed) is compared with the 12 codes
// and the matches counted in byte counters, which are added up every 255 steps (before they can
// wrap). Returns false, with `frame` partly counted, when an observed cell has a class out of
// range (the caller then counts cell by cell, which names the cell).
bool CountLanes(const std::uint8_t* predicted, const std::uint8_t* truth,
                const std::uint8_t* observed, std::size_t end, Confusion& frame) {
  const Bytes all = ~Bytes{};
  for (std::size_t i = 0; i < end;) {
    const std::size_t chunk_end = std::min(end, i + 255 * 16);
    Bytes count[kCodes] = {};
    Bytes bad = {};
    for (; i < chunk_end; i += 16) {
      Bytes t, p, o = all;
      std::memcpy(&t, truth + i, 16);
      std::memcpy(&p, predicted + i, 16);
      if (observed) {
        std::memcpy(&o, observed + i, 16);
        o = reinterpret_cast<Bytes>(o != 0);
      }
      bad |= o & reinterpret_cast<Bytes>((t >= kNumTruthClasses) | (p >= kNumPredictedClasses));
      const Bytes code = ((t << 2) | p) | (~o & 15);
      for (int k = 0; k < kCodes; ++k)
        count[k] -= reinterpret_cast<Bytes>(code == static_cast<std::uint8_t>(k));
    }
    for (int lane = 0; lane < 16; ++lane)
      if (bad[lane]) return false;
    for (int k = 0; k < kCodes; ++k)
      for (int lane = 0; lane < 16; ++lane)
        frame[k / kNumPredictedClasses][k % kNumPredictedClasses] += count[k][lane];
  }
  return true;
}

}  // namespace

void CellClassificationAccumulator::AddFrame(std::span<const std::uint8_t> predicted,
                                             std::span<const std::uint8_t> truth,
                                             std::span<const std::uint8_t> observed) {
  if (predicted.size() != truth.size() || (!observed.empty() && observed.size() != truth.size()))
    throw std::invalid_argument("CellClassificationAccumulator::AddFrame: sizes differ (" +
                                std::to_string(predicted.size()) + " predicted, " +
                                std::to_string(truth.size()) + " truth, " +
                                std::to_string(observed.size()) + " observed)");
  static_assert(kNumPredictedClasses == 4 && kCodes < 15, "CountLanes' codes");
  // Counted into a table of this frame first, so that a refused frame leaves nothing counted.
  // The cells on lanes first; the rest (or all, when the lanes met a bad class) one by one.
  Confusion frame{};
  std::size_t first = truth.size() - truth.size() % 16;
  if (!CountLanes(predicted.data(), truth.data(), observed.empty() ? nullptr : observed.data(),
                  first, frame)) {
    frame = {};
    first = 0;
  }
  for (std::size_t i = first; i < truth.size(); ++i) {
    if (!observed.empty() && observed[i] == 0) continue;
    if (truth[i] >= kNumTruthClasses || predicted[i] >= kNumPredictedClasses)
      throw std::invalid_argument("CellClassificationAccumulator::AddFrame: cell " +
                                  std::to_string(i) + " has class out of range");
    ++frame[truth[i]][predicted[i]];
  }
  std::int64_t cells = 0;
  for (int t = 0; t < kNumTruthClasses; ++t) {
    for (int p = 0; p < kNumPredictedClasses; ++p) {
      m_.confusion[t][p] += frame[t][p];
      cells += frame[t][p];
    }
  }
  m_.cells += cells;
  ++m_.frames;
}

CellMetrics CellClassificationAccumulator::Result() const {
  CellMetrics m = m_;
  auto ratio = [](std::int64_t num, std::int64_t den) -> std::optional<double> {
    if (den == 0) return std::nullopt;
    return static_cast<double>(num) / static_cast<double>(den);
  };
  auto scores = [&](int k, std::optional<double>& precision, std::optional<double>& recall,
                    std::optional<double>& f1) {
    std::int64_t predicted = 0, actual = 0;
    for (int t = 0; t < kNumTruthClasses; ++t) predicted += m.confusion[t][k];
    for (int p = 0; p < kNumPredictedClasses; ++p) actual += m.confusion[k][p];
    precision = ratio(m.confusion[k][k], predicted);
    recall = ratio(m.confusion[k][k], actual);
    // F1 = 2 TP / (2 TP + FP + FN); defined whenever the class occurs in truth or prediction.
    f1 = ratio(2 * m.confusion[k][k], predicted + actual);
  };
  scores(static_cast<int>(CellClass::kDynamic), m.dynamic_precision, m.dynamic_recall,
         m.dynamic_f1);
  scores(static_cast<int>(CellClass::kStatic), m.static_precision, m.static_recall, m.static_f1);
  std::int64_t correct = 0;
  for (int k = 0; k < kNumTruthClasses; ++k) correct += m.confusion[k][k];
  m.accuracy = ratio(correct, m.cells);
  return m;
}

void to_json(nlohmann::json& j, const CellMetrics& m) {
  j = nlohmann::json{{"confusion_truth_by_predicted", m.confusion},
                     {"confusion_rows", {"free", "static", "dynamic"}},
                     {"confusion_columns", {"free", "static", "dynamic", "unknown"}},
                     {"cells", m.cells},
                     {"frames", m.frames},
                     {"dynamic_precision", OptToJson(m.dynamic_precision)},
                     {"dynamic_recall", OptToJson(m.dynamic_recall)},
                     {"dynamic_f1", OptToJson(m.dynamic_f1)},
                     {"static_precision", OptToJson(m.static_precision)},
                     {"static_recall", OptToJson(m.static_recall)},
                     {"static_f1", OptToJson(m.static_f1)},
                     {"accuracy", OptToJson(m.accuracy)}};
}

void from_json(const nlohmann::json& j, CellMetrics& m) {
  j.at("confusion_truth_by_predicted").get_to(m.confusion);
  j.at("cells").get_to(m.cells);
  j.at("frames").get_to(m.frames);
  m.dynamic_precision = OptFromJson(j, "dynamic_precision");
  m.dynamic_recall = OptFromJson(j, "dynamic_recall");
  m.dynamic_f1 = OptFromJson(j, "dynamic_f1");
  m.static_precision = OptFromJson(j, "static_precision");
  m.static_recall = OptFromJson(j, "static_recall");
  m.static_f1 = OptFromJson(j, "static_f1");
  m.accuracy = OptFromJson(j, "accuracy");
}

}  // namespace dualgrid::eval
