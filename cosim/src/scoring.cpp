#include "dualgrid/cosim/scoring.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "dualgrid/cosim/recorded_source.hpp"

namespace dualgrid::cosim {

void TakeSnapshot(const filter::DynamicGrid& grid, bool with_velocity, GridSnapshot& s) {
  // First: classes never stand beside masses they were not taken from (even if a step throws).
  s.classes.clear();
  s.classes_threshold = std::numeric_limits<double>::quiet_NaN();
  s.cells_x = grid.cells_x();
  s.cells_y = grid.cells_y();
  s.resolution = grid.resolution();
  s.origin_ix = grid.origin_index()[0];
  s.origin_iy = grid.origin_index()[1];
  s.origin = grid.CellCenter({0, 0}) - Position::Constant(0.5 * s.resolution);
  const std::size_t n = static_cast<std::size_t>(s.cells_x) * s.cells_y;
  s.free.resize(n);
  s.static_occ.resize(n);
  s.dynamic.resize(n);
  s.observed.resize(n);
  grid.ExportMasses(s.free, s.static_occ, s.dynamic, s.observed);
  s.mean_vx.clear();
  s.mean_vy.clear();
  if (with_velocity) TakeVelocities(grid, s);
}

void ClassifySnapshot(double threshold, GridSnapshot& s) {
  s.classes.resize(s.dynamic.size());
  eval::ClassifyCells(s.free, s.static_occ, s.dynamic, threshold, s.classes);
  s.classes_threshold = threshold;
}

void TakeVelocities(const filter::DynamicGrid& grid, GridSnapshot& s) {
  const std::size_t n = static_cast<std::size_t>(s.cells_x) * s.cells_y;
  s.mean_vx.resize(n);
  s.mean_vy.resize(n);
  grid.ExportMeanVelocities(s.mean_vx, s.mean_vy);  // Cell()'s mean_velocity, as float
}

namespace {

// A box overlaps the grid rectangle (conservative: its bounding circle).
bool NearGrid(const OrientedBox& b, const Position& lo, const Position& hi) {
  const double r = 0.5 * std::hypot(b.length, b.width);
  return b.center.x() + r >= lo.x() && b.center.x() - r <= hi.x() && b.center.y() + r >= lo.y() &&
         b.center.y() - r <= hi.y();
}

}  // namespace

CellWindow CellWindow::Around(const OrientedBox& box, const filter::DynamicGrid& grid) {
  // The box's bounding rectangle in cells, widened by one cell on each side: a particle lies in
  // its cell up to float rounding (micrometres), far less than the cell of margin.
  Position lo = box.center, hi = box.center;
  for (const Position& c : box.Corners()) {
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c);
  }
  const double r = grid.resolution();
  const Position c0 = grid.CellCenter({0, 0});  // cell (x, y) spans c0 + (x, y) r +- r / 2
  const auto index = [&](double v, double c) { return std::floor((v - c) / r + 0.5); };
  CellWindow w;
  if (!lo.allFinite() || !hi.allFinite()) return w;  // an empty window
  w.x0 = index(lo.x(), c0.x()) - 1.0;
  w.x1 = index(hi.x(), c0.x()) + 1.0;
  w.y0 = index(lo.y(), c0.y()) - 1.0;
  w.y1 = index(hi.y(), c0.y()) + 1.0;
  return w;
}

std::vector<std::uint8_t> TruthClasses(const GridSnapshot& grid, const GridFrame& g,
                                       const sim::Frame& frame, const sim::ScenarioSpec& spec) {
  const Position lo = grid.origin;
  const Position hi = lo + Position(grid.cells_x, grid.cells_y) * grid.resolution;
  std::vector<OrientedBox> moving, stationary;
  // A vehicle slower than 0.5 m/s is stationary (the filter cannot call it dynamic either).
  for (const auto& v : frame.vehicles) {
    const OrientedBox b = g.ToGrid(v.box);
    if (NearGrid(b, lo, hi)) (v.velocity.norm() > 0.5 ? moving : stationary).push_back(b);
  }
  for (const auto& p : spec.parked) {
    const OrientedBox b = g.ToGrid(p.box);
    if (NearGrid(b, lo, hi)) stationary.push_back(b);
  }
  for (const auto& rail : spec.guard_rails) {
    for (std::size_t k = 0; k + 1 < rail.points.size(); ++k) {
      // Clip the segment to the grid's x range so the box stays small, then make it one cell
      // wide so that the rail marks one row of cells.
      Position a = g.ToGrid(rail.points[k]), b = g.ToGrid(rail.points[k + 1]);
      const Vector2 d = b - a;
      if (std::abs(d.x()) > 1e-9) {
        const double t0 = std::clamp((lo.x() - a.x()) / d.x(), 0.0, 1.0);
        const double t1 = std::clamp((hi.x() - a.x()) / d.x(), 0.0, 1.0);
        const Position a2 = a + std::min(t0, t1) * d, b2 = a + std::max(t0, t1) * d;
        a = a2;
        b = b2;
      }
      const double len = (b - a).norm();
      if (len < 1e-6) continue;
      const OrientedBox box{0.5 * (a + b), std::atan2(b.y() - a.y(), b.x() - a.x()), len,
                            grid.resolution};
      if (NearGrid(box, lo, hi)) stationary.push_back(box);
    }
  }
  std::vector<std::uint8_t> out(grid.free.size());
  eval::RasterizeTruth(
      {grid.origin_ix, grid.origin_iy, grid.resolution, grid.cells_x, grid.cells_y}, moving,
      stationary, out);
  return out;
}

void DynamicParticles(const filter::DynamicGrid& grid, std::span<const std::uint8_t> classes,
                      const std::optional<OrientedBox>& exclude,
                      std::vector<eval::WeightedParticle>* out, eval::PointCells* cells) {
  if (classes.size() != static_cast<std::size_t>(grid.cells_x()) * grid.cells_y())
    throw std::invalid_argument("DynamicParticles: " + std::to_string(classes.size()) +
                                " cell classes for a grid of " +
                                std::to_string(grid.cells_x() * grid.cells_y()) + " cells");
  const std::optional<BoxTest> ego = exclude ? std::optional<BoxTest>(*exclude) : std::nullopt;
  const std::optional<CellWindow> near_ego =
      exclude ? std::optional<CellWindow>(CellWindow::Around(*exclude, grid)) : std::nullopt;
  // Cell by cell (the particles are sorted by cell): only the few dynamic cells' particles are
  // visited, in the particles' order. kDynamic is ClassifyCell's first test, dynamic > threshold.
  // Only the particles of cells near the ego box take its test (the others are outside it).
  // Written through a pointer into `out`, grown ahead of each cell (its old entries are
  // overwritten, never read; the vector is reused per step, so it grows past the last call's size
  // only), not by push_back: its end pointer, stored per particle, would make the compiler reload
  // the grid's arrays per particle.
  constexpr auto kDynamic = static_cast<std::uint8_t>(eval::CellClass::kDynamic);
  const int cells_x = grid.cells_x();
  if (cells) {
    cells->origin = grid.CellCenter({0, 0}) - Position::Constant(0.5 * grid.resolution());
    cells->side = grid.resolution();
    cells->runs.clear();
  }
  std::size_t m = 0;  // particles written
  grid.ForEachWeightedCellWhere(
      classes, filter::ByteIs{kDynamic}, [&](std::size_t k, std::int64_t first, std::int64_t last) {
        const auto count = static_cast<std::size_t>(last - first);
        if (m + count > out->size()) out->resize(m + count);  // past the last call's size only
        eval::WeightedParticle* const dst = out->data();
        const auto cx = static_cast<int>(k % cells_x), cy = static_cast<int>(k / cells_x);
        const bool test_ego = near_ego && near_ego->Holds(cx, cy);
        std::size_t j = m;
        for (std::int64_t i = first; i < last; ++i) {
          const filter::ParticleView p = grid.WeightedParticle(static_cast<std::size_t>(i));
          if (!(p.weight > 0.0f)) continue;
          if (test_ego && ego->Contains(p.position)) continue;
          // Scalar double stores: Eigen's vector stores may alias anything, which would make
          // the compiler reload the grid's arrays per particle.
          eval::WeightedParticle& d = dst[j++];
          d.position.x() = p.position.x();
          d.position.y() = p.position.y();
          d.velocity.x() = p.velocity.x();
          d.velocity.y() = p.velocity.y();
          d.weight = p.weight;
        }
        if (cells && j > m) cells->runs.push_back({cx, cy, static_cast<int>(m)});
        m = j;
      });
  out->resize(m);
}

ModeScorer::ModeScorer(const scenario::EvaluationConfig& config)
    : config_(config),
      clusterer_(config.dbscan, config.min_cluster_mass),
      tracking_(config.tracking) {}

void ModeScorer::AddFrame(double time, const filter::DynamicGrid& grid,
                          const GridSnapshot& snapshot,
                          const std::vector<eval::TruthObject>& objects,
                          const std::vector<std::uint8_t>& truth_classes,
                          const OrientedBox& ego_box) {
  // Paper Sec. V: particles of cells with P(dynamic) above the threshold are clustered.
  // The weighted persistent particles (before resampling, when all weights become equal), so
  // that the cluster means are the paper's weighted averages and exclude this cycle's births.
  std::span<const std::uint8_t> classes = snapshot.classes;
  if (classes.size() != snapshot.dynamic.size() ||
      snapshot.classes_threshold != config_.dynamic_threshold) {
    predicted_.resize(snapshot.dynamic.size());
    eval::ClassifyCells(snapshot.free, snapshot.static_occ, snapshot.dynamic,
                        config_.dynamic_threshold, predicted_);
    classes = predicted_;
  }
  DynamicParticles(grid, classes, ego_box, &dynamic_particles_, &dynamic_cells_);
  clusters_ = clusterer_.Run(dynamic_particles_, dynamic_cells_);
  association_ = tracking_.AddFrame(time, clusters_, objects);
  cells_.AddFrame(classes, truth_classes, snapshot.observed);
}

void ModeScorer::AddPoints(const filter::DynamicGrid& grid, const GridSnapshot& snapshot,
                           const std::vector<Position>& positions, const std::vector<int>& labels,
                           const OrientedBox& ego_box) {
  if (!points_) points_.emplace();
  const BoxTest ego(ego_box);
  for (std::size_t i = 0; i < positions.size(); ++i) {
    if (labels[i] < 0 || ego.Contains(positions[i])) continue;
    const auto cell = grid.CellOf(positions[i]);
    const bool dynamic =
        cell && snapshot.dynamic[static_cast<std::size_t>(cell->y) * snapshot.cells_x + cell->x] >
                    config_.dynamic_threshold;
    points_->Add(IsMovingLabel(labels[i]), cell.has_value(), dynamic);
  }
  points_->EndFrame();
}

eval::ScenarioMetrics ModeScorer::Result() const {
  eval::ScenarioMetrics m = tracking_.Result();
  m.cells = cells_.Result();
  if (points_) m.points = points_->Result();
  return m;
}

}  // namespace dualgrid::cosim
