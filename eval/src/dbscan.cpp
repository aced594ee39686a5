#include "dualgrid/eval/dbscan.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "dualgrid/core/parallel.hpp"
#include "dualgrid/core/validation.hpp"

namespace dualgrid::eval {

namespace {

std::uint64_t PackKey(std::int64_t ix, std::int64_t iy) {
  // Two's-complement truncation to 32 bits is injective for |index| < 2^31 cells.
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(ix)) << 32) |
         static_cast<std::uint32_t>(iy);
}

// static_cast<std::int64_t>(std::floor(v)), the same value, without the libm call that baseline
// x86-64 (no rounding instruction) makes of std::floor (4 per point showed in the profiles):
// truncation towards zero, minus one where that rounded a negative non-integer up. Exact for
// |v| < 2^62 (the truncation and its conversion back are exact there); beyond, std::floor.
std::int64_t FloorToInt(double v) {
  if (!(std::abs(v) < 0x1p62)) return static_cast<std::int64_t>(std::floor(v));
  const auto t = static_cast<std::int64_t>(v);
  return t - static_cast<std::int64_t>(static_cast<double>(t) > v);
}

// The cell offsets of Chebyshev distance 1 and 2 in the upper half plane (dy > 0, or dy == 0 and
// dx > 0): of two cells at one of these distances, exactly one sees the other at such an offset.
constexpr int kMaxReach = 4;  // the widest neighbour block: 9 x 9 cells

// Ring-1 components beyond which OuterRingCells tries every core cell (its pairs of rectangles
// grow with the square of their count).
constexpr std::size_t kMaxRing1Boxes = 64;

// Relative margin of a point outside its given cell (RunInCells), in cell sides: far above the
// rounding of a position stored as a float offset (micrometres on a 0.5 m cell).
constexpr double kCellSlack = 1e-3;

// Strict order used to break distance ties between core points: lexicographic (x, y).
bool LexLess(const Position& a, const Position& b) {
  return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
}

}  // namespace

bool DbscanParams::IsValid(std::string* error) const {
  FieldCheck c;
  c.Positive("eps", eps, "m");
  c.AtLeast("min_points", min_points, 1);
  c.NonNegative("min_weight", min_weight);
  return c.Done(error);
}

void to_json(nlohmann::json& j, const DbscanParams& p) {
  j = {{"eps", p.eps}, {"min_points", p.min_points}, {"min_weight", p.min_weight}};
}

Dbscan::Dbscan(const DbscanParams& params) : params_(params) {
  std::string error;
  if (!params_.IsValid(&error)) throw std::invalid_argument("DbscanParams: " + error);
  inv_eps_ = 1.0 / params_.eps;
}

int Dbscan::CellTable::Build(std::span<const std::int64_t> ix, std::span<const std::int64_t> iy,
                             int pad, std::span<int> id) {
  const std::size_t n = ix.size();
  map.clear();
  for (const std::size_t k : used) cells[k] = -1;  // every entry is -1 again
  used.clear();
  std::int64_t lo_x = 0, hi_x = -1, lo_y = 0, hi_y = -1;
  for (std::size_t i = 0; i < n; ++i) {
    lo_x = i == 0 ? ix[i] : std::min(lo_x, ix[i]);
    hi_x = i == 0 ? ix[i] : std::max(hi_x, ix[i]);
    lo_y = i == 0 ? iy[i] : std::min(lo_y, iy[i]);
    hi_y = i == 0 ? iy[i] : std::max(hi_y, iy[i]);
  }
  // Spans as doubles: far-apart points must not overflow the product.
  const double area = (static_cast<double>(hi_x) - static_cast<double>(lo_x) + 1.0 + 2.0 * pad) *
                      (static_cast<double>(hi_y) - static_cast<double>(lo_y) + 1.0 + 2.0 * pad);
  dense = n > 0 && area <= 8.0 * static_cast<double>(n) + 65536.0;
  int count = 0;
  if (dense) {
    x0 = lo_x - pad;
    y0 = lo_y - pad;
    w = hi_x - lo_x + 1 + 2 * pad;
    if (cells.size() < static_cast<std::size_t>(area))
      cells.resize(static_cast<std::size_t>(area), -1);
    for (std::size_t i = 0; i < n; ++i) {
      const auto k = static_cast<std::size_t>((iy[i] - y0) * w + (ix[i] - x0));
      int& c = cells[k];
      if (c < 0) {
        c = count++;
        used.push_back(k);
      }
      id[i] = c;
    }
    return count;
  }
  for (std::size_t i = 0; i < n; ++i) {
    const auto [it, inserted] = map.try_emplace(PackKey(ix[i], iy[i]), count);
    if (inserted) ++count;
    id[i] = it->second;
  }
  return count;
}

// Inline (here, their only user): the component search calls Find and FindRoot for every pair
// of nearby fine cells.
[[gnu::always_inline]] inline int Dbscan::CellTable::Find(std::int64_t x, std::int64_t y) const {
  if (dense) return cells[static_cast<std::size_t>((y - y0) * w + (x - x0))];
  const auto it = map.find(PackKey(x, y));
  return it == map.end() ? -1 : it->second;
}

void Dbscan::NearBuckets(int num_buckets) {
  // The point's own cell first: in a dense cluster the core test then stops after a few
  // distances instead of scanning the far corners of the neighbouring cells.
  static constexpr int kOrder[kNear][2] = {{0, 0}, {-1, -1}, {-1, 0}, {-1, 1}, {0, -1},
                                           {0, 1}, {1, -1},  {1, 0},  {1, 1}};
  near_.resize(static_cast<std::size_t>(num_buckets) * kNear);
  for (int b = 0; b < num_buckets; ++b) {
    const int first = sorted_[start_[b]];  // any member: all share the bucket's coordinates
    int* out = &near_[static_cast<std::size_t>(b) * kNear];
    int k = 0;
    for (const auto& [dx, dy] : kOrder) {
      const int nb = buckets_.Find(ix_[first] + dx, iy_[first] + dy);
      if (nb >= 0) out[k++] = nb;
    }
    for (; k < kNear; ++k) out[k] = -1;
  }
}

template <typename F>
void Dbscan::ForEachNeighbour(int b, int s, F&& f) const {
  const double eps2 = params_.eps * params_.eps;
  const Position p = sorted_pos_[s];
  const int* near = &near_[static_cast<std::size_t>(b) * kNear];
  for (int k = 0; k < kNear && near[k] >= 0; ++k)
    for (int t = start_[near[k]]; t < start_[near[k] + 1]; ++t)
      if ((sorted_pos_[t] - p).squaredNorm() <= eps2 && !f(t)) return;
}

[[gnu::always_inline]] inline int Dbscan::FindRoot(int c) {
  while (parent_[c] != c) {
    parent_[c] = parent_[parent_[c]];  // path halving
    c = parent_[c];
  }
  return c;
}

double Dbscan::InvFineSide() const {
  // Side h < eps / sqrt(2) with a relative margin far above rounding: two points of one cell are
  // closer than eps * (1 - 1e-9), so squaredNorm() <= eps^2 holds for them whatever the rounding.
  return std::sqrt(2.0) / (params_.eps * (1.0 - 1e-9));
}

void Dbscan::FineCells(std::span<const Position> points) {
  const double inv_h = InvFineSide();
  const std::size_t n = points.size();
  fx_.resize(n);
  fy_.resize(n);
  fine_cell_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    fx_[i] = FloorToInt(points[i].x() * inv_h);
    fy_[i] = FloorToInt(points[i].y() * inv_h);
  }
  SetBlock(2, 0.0);
  whole_core_ = true;
  sorted_is_identity_ = false;
  const int cells = fine_.Build(fx_, fy_, reach_, fine_cell_);
  fine_start_.assign(cells + 1, 0);
  for (std::size_t i = 0; i < n; ++i) ++fine_start_[fine_cell_[i] + 1];
  for (int c = 0; c < cells; ++c) fine_start_[c + 1] += fine_start_[c];
  fine_sorted_.resize(n);
  parent_.assign(fine_start_.begin(), fine_start_.end() - 1);  // borrowed as the cursor
  for (std::size_t i = 0; i < n; ++i) fine_sorted_[parent_[fine_cell_[i]]++] = static_cast<int>(i);
  cx_.resize(cells);
  cy_.resize(cells);
  for (int c = 0; c < cells; ++c) {
    const int member = fine_sorted_[fine_start_[c]];  // all members share the coordinates
    cx_[c] = fx_[member];
    cy_[c] = fy_[member];
  }
}

void Dbscan::SetBlock(int reach, double side) {
  if (reach == reach_ && side == block_side_) return;
  reach_ = reach;
  block_side_ = side;
  // The gap between cells d apart along an axis (less the slack of both points), 0 if adjacent.
  const auto gap = [&](int d) {
    return side > 0.0 ? std::max((std::abs(d) - 1 - 2.0 * kCellSlack) * side, 0.0) : 0.0;
  };
  const double eps2 = params_.eps * params_.eps * (1.0 + 1e-9);
  const auto near = [&](int dx, int dy) { return gap(dx) * gap(dx) + gap(dy) * gap(dy) <= eps2; };
  half_.clear();
  block_.clear();
  ring_start_.assign(1, 0);
  for (int r = 1; r <= reach; ++r) {
    for (int dy = 0; dy <= r; ++dy)
      for (int dx = -r; dx <= r; ++dx)
        if (std::max(std::abs(dx), dy) == r && (dy > 0 || dx > 0) && near(dx, dy))
          half_.push_back({dx, dy});
    ring_start_.push_back(static_cast<int>(half_.size()));
  }
  for (int dx = -reach; dx <= reach; ++dx)
    for (int dy = -reach; dy <= reach; ++dy)
      if (near(dx, dy)) block_.push_back({dx, dy});
}

bool Dbscan::GivenCells(std::span<const Position> points, const PointCells& given) {
  const int n = static_cast<int>(points.size());
  const int cells = static_cast<int>(given.runs.size());
  const double inv_side = 1.0 / given.side;
  cx_.resize(cells);
  cy_.resize(cells);
  fine_start_.resize(cells + 1);
  bool inside = true;
  for (int c = 0; c < cells; ++c) {
    const CellRun& run = given.runs[c];
    cx_[c] = run.x;
    cy_[c] = run.y;
    fine_start_[c] = run.first;
    const int last = c + 1 < cells ? given.runs[c + 1].first : n;
    // The position in cell sides, relative to the cell, is a non-decreasing function of the
    // coordinate (a subtraction, a product by a positive factor, a subtraction: each rounded
    // monotonically), so the run's extreme coordinates (finite: CheckInput) give its extremes.
    double lo_x = points[run.first].x(), hi_x = lo_x, lo_y = points[run.first].y(), hi_y = lo_y;
    for (int i = run.first + 1; i < last; ++i) {
      lo_x = std::min(lo_x, points[i].x());
      hi_x = std::max(hi_x, points[i].x());
      lo_y = std::min(lo_y, points[i].y());
      hi_y = std::max(hi_y, points[i].y());
    }
    const double x = static_cast<double>(run.x), y = static_cast<double>(run.y);
    const auto u = [&](double v) { return (v - given.origin.x()) * inv_side - x; };
    const auto w = [&](double v) { return (v - given.origin.y()) * inv_side - y; };
    inside &= (u(lo_x) >= -kCellSlack) & (u(hi_x) <= 1.0 + kCellSlack) & (w(lo_y) >= -kCellSlack) &
              (w(hi_y) <= 1.0 + kCellSlack);
  }
  fine_start_[cells] = n;
  if (!inside) return false;
  fine_cell_.resize(cells);  // the run of each cell (its id is its first run's)
  if (fine_.Build(cx_, cy_, reach_, fine_cell_) != cells) return false;
  fine_sorted_.resize(n);
  for (int i = 0; i < n; ++i) fine_sorted_[i] = i;
  sorted_is_identity_ = true;
  return true;
}

int Dbscan::CoreComponents(std::span<const Position> points) {
  // Cells up to reach_ apart can hold neighbours (FineCells: h < eps < 2 h, so a 5 x 5 block).
  const int cells = static_cast<int>(fine_start_.size()) - 1;
  // Each cell's core points, in input order (a stable filter of fine_sorted_).
  // A cell that CountCore made core as a whole is copied without its flags.
  core_start_.resize(cells + 1);
  core_sorted_.resize(fine_sorted_.size());
  const int* const sorted = fine_sorted_.data();
  int* const core_sorted = core_sorted_.data();
  int num_core = 0;
  for (int c = 0; c < cells; ++c) {
    core_start_[c] = num_core;
    const int first = fine_start_[c], last = fine_start_[c + 1];
    if (whole_cells_core_ && last - first >= params_.min_points) {
      std::copy(sorted + first, sorted + last, core_sorted + num_core);
      num_core += last - first;
      continue;
    }
    for (int k = first; k < last; ++k) {
      const int i = sorted[k];
      core_sorted[num_core] = i;
      num_core += core_[i];
    }
  }
  core_start_[cells] = num_core;
  core_sorted_.resize(num_core);
  parent_.resize(cells);
  for (int c = 0; c < cells; ++c) parent_[c] = c;
  // Cells without core points take no part (they stay their own roots and get no component).
  core_cells_.clear();
  for (int c = 0; c < cells; ++c)
    if (core_start_[c] < core_start_[c + 1]) core_cells_.push_back(c);
  half_delta_.resize(half_.size());
  for (std::size_t k = 0; k < half_.size(); ++k)
    half_delta_[k] = half_[k].dy * fine_.w + half_[k].dx;
  // Adjacent cells first (they almost always link); the outer rings then only from the cells
  // that lie within reach of another ring-1 component (OuterRingCells): every other pair of cells
  // in the outer rings is joined already, and the components (a partition) do not depend on the
  // order or the number of the links tried.
  JoinRings(points, 1, 1, core_cells_);
  if (reach_ > 1) JoinRings(points, 2, reach_, OuterRingCells());
  // Compact component ids in cell order; each cell's core points take its component (a fill
  // where they are consecutive input indices: all of a given cell's points).
  int num_components = 0;
  std::vector<int>& id_of_root = root_component_;
  id_of_root.assign(cells, -1);
  int* const component_of = component_.data();
  for (int c = 0; c < cells; ++c) {
    const int first = core_start_[c], last = core_start_[c + 1];
    if (first == last) continue;
    const int r = FindRoot(c);
    if (id_of_root[r] < 0) id_of_root[r] = num_components++;
    const int component = id_of_root[r];
    if (sorted_is_identity_ && last - first == fine_start_[c + 1] - fine_start_[c]) {
      std::fill(component_of + fine_start_[c], component_of + fine_start_[c + 1], component);
      continue;
    }
    for (int s = first; s < last; ++s) component_of[core_sorted[s]] = component;
  }
  return num_components;
}

void Dbscan::JoinRings(std::span<const Position> points, int first_ring, int last_ring,
                       std::span<const int> from) {
  const double eps2 = params_.eps * params_.eps;
  auto linked = [&](int a, int b) {  // some core pair of cells a and b within eps
    for (int s = core_start_[a]; s < core_start_[a + 1]; ++s)
      for (int t = core_start_[b]; t < core_start_[b + 1]; ++t)
        if ((points[core_sorted_[s]] - points[core_sorted_[t]]).squaredNorm() <= eps2) return true;
    return false;
  };
  // Each unordered pair of cells once: from the cell that sees the other at an offset of the
  // upper half plane (half_). In a dense table, a cell's neighbours are at fixed distances from
  // its entry.
  for (int r = first_ring; r <= last_ring; ++r) {
    for (const int a : from) {
      int ra = FindRoot(a);
      const auto join = [&](int b) {
        if (b < 0 || core_start_[b] == core_start_[b + 1]) return;
        const int rb = FindRoot(b);
        if (ra == rb || !linked(a, b)) return;
        parent_[std::max(ra, rb)] = std::min(ra, rb);
        ra = std::min(ra, rb);
      };
      if (fine_.dense) {
        const int* const at =
            fine_.cells.data() + ((cy_[a] - fine_.y0) * fine_.w + (cx_[a] - fine_.x0));
        for (int k = ring_start_[r - 1]; k < ring_start_[r]; ++k) join(at[half_delta_[k]]);
      } else {
        for (int k = ring_start_[r - 1]; k < ring_start_[r]; ++k)
          join(fine_.Find(cx_[a] + half_[k].dx, cy_[a] + half_[k].dy));
      }
    }
  }
}

std::span<const int> Dbscan::OuterRingCells() {
  // The ring-1 components and their bounding rectangles in cells. A pair of cells of two
  // components lies within reach_ cells along both axes, so each of its cells lies within reach_
  // of the other's rectangle; cells within reach_ of no other rectangle need no outer ring.
  ring1_of_.resize(core_cells_.size());
  ring1_boxes_.clear();
  root_component_.assign(parent_.size(), -1);
  for (std::size_t k = 0; k < core_cells_.size(); ++k) {
    const int a = core_cells_[k];
    int& id = root_component_[FindRoot(a)];
    if (id < 0) {
      id = static_cast<int>(ring1_boxes_.size());
      ring1_boxes_.push_back({cx_[a], cx_[a], cy_[a], cy_[a]});
    }
    CellBox& b = ring1_boxes_[id];
    b.x0 = std::min(b.x0, cx_[a]);
    b.x1 = std::max(b.x1, cx_[a]);
    b.y0 = std::min(b.y0, cy_[a]);
    b.y1 = std::max(b.y1, cy_[a]);
    ring1_of_[k] = id;
  }
  const std::size_t boxes = ring1_boxes_.size();
  if (boxes > kMaxRing1Boxes) return core_cells_;  // the pairs of rectangles would cost more
  // Per component, the others whose rectangles come within reach_ of its own (CSR lists).
  const std::int64_t reach = reach_;
  const auto near = [reach](const CellBox& b, std::int64_t x0, std::int64_t x1, std::int64_t y0,
                            std::int64_t y1) {
    return x0 <= b.x1 + reach && x1 >= b.x0 - reach && y0 <= b.y1 + reach && y1 >= b.y0 - reach;
  };
  near_start_.assign(boxes + 1, 0);
  near_boxes_.clear();
  for (std::size_t i = 0; i < boxes; ++i) {
    const CellBox& bi = ring1_boxes_[i];
    for (std::size_t j = 0; j < boxes; ++j)
      if (j != i && near(ring1_boxes_[j], bi.x0, bi.x1, bi.y0, bi.y1))
        near_boxes_.push_back(static_cast<int>(j));
    near_start_[i + 1] = static_cast<int>(near_boxes_.size());
  }
  outer_cells_.clear();
  for (std::size_t k = 0; k < core_cells_.size(); ++k) {
    const int a = core_cells_[k], id = ring1_of_[k];
    for (int m = near_start_[id]; m < near_start_[id + 1]; ++m) {
      if (near(ring1_boxes_[near_boxes_[m]], cx_[a], cx_[a], cy_[a], cy_[a])) {
        outer_cells_.push_back(a);
        break;
      }
    }
  }
  return outer_cells_;
}

template <typename F>
void Dbscan::ForEachFineNeighbour(std::span<const Position> points, int c, int i, F&& f) const {
  const double eps2 = params_.eps * params_.eps;
  const Position p = points[i];
  const std::int64_t x = cx_[c], y = cy_[c];
  for (const Offset& d : block_) {
    const int b = d.dx == 0 && d.dy == 0 ? c : fine_.Find(x + d.dx, y + d.dy);
    if (b < 0) continue;
    for (int k = fine_start_[b]; k < fine_start_[b + 1]; ++k) {
      const int j = fine_sorted_[k];
      if ((points[j] - p).squaredNorm() <= eps2 && !f(j)) return;
    }
  }
}

void Dbscan::CountCore(std::span<const Position> points) {
  // A fine cell holding min_points points makes them all core when its diameter is below eps:
  // they are within eps of each other (Gunawan's rule). The points of the other cells count their
  // neighbours until min_points.
  const int cells = static_cast<int>(fine_start_.size()) - 1;
  // Through local pointers: the flags' byte stores could alias the members, which the compiler
  // would then reload per point.
  const int* const start = fine_start_.data();
  const int* const sorted = fine_sorted_.data();
  std::uint8_t* const core = core_.data();
  ParallelFor(
      cells, Schedule::kDynamic,
      [&](std::int64_t c64) {
        const int c = static_cast<int>(c64);
        const int first = start[c], last = start[c + 1];
        if (whole_core_ && last - first >= params_.min_points) {
          for (int k = first; k < last; ++k) core[sorted[k]] = 1;
          return;
        }
        for (int k = first; k < last; ++k) {
          const int i = sorted[k];
          int count = 0;
          ForEachFineNeighbour(points, c, i, [&](int) {
            if (++count < params_.min_points) return true;
            core[i] = 1;
            return false;
          });
        }
      },
      /*worth=*/true, /*chunk=*/8);
}

void Dbscan::WeightedCore(std::span<const Position> points, std::span<const double> weights) {
  const int n = static_cast<int>(points.size());
  // Index cells of side eps: every neighbour lies in the 3 x 3 block around a point's cell. The
  // neighbours are visited in a fixed order (own cell first, then NearBuckets' order, input order
  // within a cell) and the weights summed in it, so that the sum is the same on every run.
  ix_.resize(n);
  iy_.resize(n);
  bucket_.resize(n);
  for (int i = 0; i < n; ++i) {
    ix_[i] = FloorToInt(points[i].x() * inv_eps_);
    iy_[i] = FloorToInt(points[i].y() * inv_eps_);
  }
  const int num_buckets = buckets_.Build(ix_, iy_, 1, bucket_);
  start_.assign(num_buckets + 1, 0);
  for (int i = 0; i < n; ++i) ++start_[bucket_[i] + 1];
  for (int b = 0; b < num_buckets; ++b) start_[b + 1] += start_[b];
  sorted_.resize(n);
  // Counting sort keeps input order inside each bucket; component_ is borrowed as the cursor.
  component_.assign(start_.begin(), start_.end() - 1);
  for (int i = 0; i < n; ++i) sorted_[component_[bucket_[i]]++] = i;
  // Positions and weights in bucket order: the neighbour scans below read them contiguously.
  sorted_pos_.resize(n);
  sorted_weight_.resize(n);
  for (int s = 0; s < n; ++s) {
    sorted_pos_[s] = points[sorted_[s]];
    sorted_weight_[s] = weights[sorted_[s]];
  }
  NearBuckets(num_buckets);
  // Bucket by bucket (a bucket's members share their neighbour buckets). Independent per point,
  // so parallel; stops counting once both criteria hold.
  ParallelFor(
      num_buckets, Schedule::kDynamic,
      [&](std::int64_t b64) {
        const int b = static_cast<int>(b64);
        for (int s = start_[b]; s < start_[b + 1]; ++s) {
          int count = 0;
          double weight = 0.0;
          ForEachNeighbour(b, s, [&](int t) {
            ++count;
            weight += sorted_weight_[t];
            const bool done = count >= params_.min_points && weight >= params_.min_weight;
            if (done) core_[sorted_[s]] = 1;
            return !done;
          });
        }
      },
      /*worth=*/true, /*chunk=*/8);
}

namespace {

void CheckInput(std::span<const Position> points, std::span<const double> weights) {
  if (!weights.empty() && weights.size() != points.size())
    throw std::invalid_argument("Dbscan::Run: " + std::to_string(weights.size()) + " weights for " +
                                std::to_string(points.size()) + " points");
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite())
      throw std::invalid_argument("Dbscan::Run: point " + std::to_string(i) + " is not finite");
  }
}

}  // namespace

std::span<const int> Dbscan::Run(std::span<const Position> points,
                                 std::span<const double> weights) {
  CheckInput(points, weights);
  FineCells(points);
  return LabelOnFineGrid(points, weights);
}

std::span<const int> Dbscan::RunInCells(std::span<const Position> points,
                                        std::span<const double> weights, const PointCells& cells) {
  CheckInput(points, weights);
  const int n = static_cast<int>(points.size());
  for (std::size_t c = 0; c < cells.runs.size(); ++c) {
    const int first = cells.runs[c].first;
    if ((c == 0 && first != 0) || first >= n || (c > 0 && first <= cells.runs[c - 1].first))
      throw std::invalid_argument("Dbscan::RunInCells: run " + std::to_string(c) +
                                  " starts at point " + std::to_string(first) + " of " +
                                  std::to_string(n) + " (need 0 first, rising, below the count)");
  }
  if (cells.runs.empty() && n > 0)
    throw std::invalid_argument("Dbscan::RunInCells: " + std::to_string(n) + " points, no run");
  // Cells up to reach apart can hold neighbours: points of cells reach + 1 apart are more than
  // reach sides minus the slack apart.
  const double eps = params_.eps, side = cells.side;
  const bool weighted = !weights.empty() && params_.min_weight > 0.0;
  if (weighted || !(side > eps / kMaxReach && std::isfinite(side))) return Run(points, weights);
  const int reach = static_cast<int>(std::floor(eps / side + 2.0 * kCellSlack)) + 1;
  if (reach > kMaxReach) return Run(points, weights);
  SetBlock(reach, side);
  // Two points of one cell (widened by the slack) are closer than eps * (1 - 1e-9), as in
  // InvFineSide.
  whole_core_ = side * (1.0 + 2.0 * kCellSlack) * std::sqrt(2.0) < eps * (1.0 - 1e-9);
  if (!GivenCells(points, cells)) return Run(points, weights);
  return LabelOnFineGrid(points, weights);
}

std::span<const int> Dbscan::LabelOnFineGrid(std::span<const Position> points,
                                             std::span<const double> weights) {
  const int n = static_cast<int>(points.size());
  // The fine grid: the core test of sparse cells, the components and the borders.
  core_.assign(n, 0);
  const bool use_weights = !weights.empty() && params_.min_weight > 0.0;
  if (use_weights)
    WeightedCore(points, weights);
  else
    CountCore(points);
  whole_cells_core_ = whole_core_ && !use_weights;

  // Clusters are the connected components of the core graph (order independent).
  component_.assign(n, kNoise);
  const int num_components = CoreComponents(points);

  // Border points join their nearest core neighbour's cluster (see class comment for ties).
  const int cells = static_cast<int>(fine_start_.size()) - 1;
  ParallelFor(
      cells, Schedule::kDynamic,
      [&](std::int64_t c64) {
        const int c = static_cast<int>(c64);
        if (core_start_[c + 1] - core_start_[c] == fine_start_[c + 1] - fine_start_[c]) return;
        for (int k = fine_start_[c]; k < fine_start_[c + 1]; ++k) {
          const int i = fine_sorted_[k];
          if (core_[i]) continue;
          double best_d2 = std::numeric_limits<double>::infinity();
          int best = -1;  // an input index
          ForEachFineNeighbour(points, c, i, [&](int j) {
            if (!core_[j]) return true;
            const double d2 = (points[j] - points[i]).squaredNorm();
            if (d2 < best_d2 || (d2 == best_d2 && LexLess(points[j], points[best]))) {
              best_d2 = d2;
              best = j;
            }
            return true;
          });
          component_[i] = best < 0 ? kNoise : component_[best];
        }
      },
      /*worth=*/true, /*chunk=*/8);

  // Final labels numbered by each cluster's lowest input index.
  relabel_.assign(num_components, kNoise);
  labels_.resize(n);
  num_clusters_ = 0;
  for (int i = 0; i < n; ++i) {
    const int c = component_[i];
    if (c == kNoise) {
      labels_[i] = kNoise;
      continue;
    }
    if (relabel_[c] == kNoise) relabel_[c] = num_clusters_++;
    labels_[i] = relabel_[c];
  }
  return labels_;
}

}  // namespace dualgrid::eval
