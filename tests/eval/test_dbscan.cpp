#include <algorithm>
#include <map>
#include <numeric>
#include <set>
#include <vector>

#include <omp.h>
#include <catch2/catch.hpp>

#include "dualgrid/core/random.hpp"
#include "dualgrid/eval/dbscan.hpp"

using dualgrid::CounterRng;
using dualgrid::Position;
using dualgrid::RngPurpose;
using dualgrid::eval::Dbscan;
using dualgrid::eval::DbscanParams;
using dualgrid::eval::kNoise;

namespace {

// Partition as a set of sets of point identities (input indices mapped through `id`), noise
// excluded: label numbering is allowed to differ between runs, the grouping is not.
std::set<std::set<int>> Partition(std::span<const int> labels, const std::vector<int>& id) {
  std::map<int, std::set<int>> groups;
  for (std::size_t i = 0; i < labels.size(); ++i) {
    if (labels[i] != kNoise) groups[labels[i]].insert(id[i]);
  }
  std::set<std::set<int>> out;
  for (auto& [l, g] : groups) out.insert(g);
  return out;
}

// With `snap`, points are rounded to a 0.5 m lattice: many exact duplicates and exact distance
// ties, as with particles concentrated in grid cells.
std::vector<Position> RandomPoints(std::uint64_t seed, int n, double extent, bool snap) {
  CounterRng rng(seed, RngPurpose::kTest, 0, 0);
  std::vector<Position> p(n);
  // A few dense blobs plus uniform background so that core, border and noise points all occur.
  for (int i = 0; i < n; ++i) {
    if (i % 3 == 0) {
      p[i] = Position(rng.Uniform(0.0, extent), rng.Uniform(0.0, extent));
    } else {
      const int blob = static_cast<int>(rng.Uniform(0.0, 4.0));
      p[i] = Position(0.25 * extent * (blob + 0.5), 0.5 * extent) +
             Position(rng.Normal(0.0, 0.8), rng.Normal(0.0, 0.8));
    }
  }
  if (snap) {
    for (Position& q : p) q = (q * 2.0).array().round() / 2.0;
  }
  return p;
}

bool LexLess(const Position& a, const Position& b) {
  return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
}

// Brute-force reference, O(n^2): core flags, core components, border -> nearest core (ties to
// the lexicographically smaller core point). Components numbered by their first core point;
// *weight_misses counts the points with min_points neighbours that the weights made non-core.
std::vector<int> ReferenceLabels(const std::vector<Position>& pts,
                                 const std::vector<double>& weights, const DbscanParams& params,
                                 int* weight_misses) {
  const int n = static_cast<int>(pts.size());
  std::vector<std::vector<int>> nb(n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      if ((pts[i] - pts[j]).norm() <= params.eps) nb[i].push_back(j);
  std::vector<bool> core(n);
  for (int i = 0; i < n; ++i) {
    double w = 0.0;
    for (const int j : nb[i]) w += weights.empty() ? 1.0 : weights[j];
    core[i] = static_cast<int>(nb[i].size()) >= params.min_points && w >= params.min_weight;
    *weight_misses += static_cast<int>(nb[i].size()) >= params.min_points && !core[i];
  }
  std::vector<int> comp(n, -1);
  int nc = 0;
  for (int i = 0; i < n; ++i) {
    if (!core[i] || comp[i] >= 0) continue;
    std::vector<int> stack = {i};
    comp[i] = nc;
    while (!stack.empty()) {
      const int a = stack.back();
      stack.pop_back();
      for (const int b : nb[a])
        if (core[b] && comp[b] < 0) comp[b] = nc, stack.push_back(b);
    }
    ++nc;
  }
  for (int i = 0; i < n; ++i) {  // border: nearest core, ties to the lexicographically smaller
    if (core[i]) continue;
    int best = -1;
    for (const int j : nb[i]) {
      if (!core[j]) continue;
      const double d = (pts[j] - pts[i]).squaredNorm();
      if (best < 0 || d < (pts[best] - pts[i]).squaredNorm() ||
          (d == (pts[best] - pts[i]).squaredNorm() && LexLess(pts[j], pts[best])))
        best = j;
    }
    if (best >= 0) comp[i] = comp[best];
  }
  return comp;
}

}  // namespace

TEST_CASE("DBSCAN params validation names the field", "[dbscan]") {
  std::string error;
  CHECK(DbscanParams{}.IsValid(&error));
  DbscanParams p;
  p.eps = 0.0;
  CHECK_FALSE(p.IsValid(&error));
  CHECK(error.find("eps") != std::string::npos);
  p = {};
  p.min_points = 0;
  CHECK_FALSE(p.IsValid(&error));
  CHECK(error.find("min_points") != std::string::npos);
  p = {};
  p.min_weight = -1.0;
  CHECK_FALSE(p.IsValid(&error));
  CHECK(error.find("min_weight") != std::string::npos);
  CHECK_THROWS_AS(Dbscan(p), std::invalid_argument);
}

TEST_CASE("DBSCAN finds two blobs and leaves isolated noise", "[dbscan]") {
  std::vector<Position> pts;
  // Blob A: 3x3 lattice with 0.5 m spacing at the origin; blob B: same at (10, 0).
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) pts.emplace_back(0.5 * i, 0.5 * j);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) pts.emplace_back(10.0 + 0.5 * i, 0.5 * j);
  pts.emplace_back(5.0, 5.0);   // isolated
  pts.emplace_back(5.0, -5.0);  // isolated
  Dbscan dbscan(DbscanParams{.eps = 1.0, .min_points = 3});
  const auto labels = dbscan.Run(pts);
  REQUIRE(dbscan.num_clusters() == 2);
  for (int i = 0; i < 9; ++i) CHECK(labels[i] == 0);
  for (int i = 9; i < 18; ++i) CHECK(labels[i] == 1);
  CHECK(labels[18] == kNoise);
  CHECK(labels[19] == kNoise);
}

TEST_CASE("DBSCAN chains through core points and respects eps exactly", "[dbscan]") {
  // Points on a line with spacing s: with min_points 3 every inner point has itself and two
  // neighbours when s <= eps, so the whole chain is one cluster; with s > eps nobody is core.
  const double spacing = GENERATE(0.5, 0.9, 1.0, 1.0001, 1.5);
  std::vector<Position> pts;
  for (int i = 0; i < 20; ++i) pts.emplace_back(spacing * i, 0.0);
  Dbscan dbscan(DbscanParams{.eps = 1.0, .min_points = 3});
  const auto labels = dbscan.Run(pts);
  if (spacing <= 1.0) {
    CHECK(dbscan.num_clusters() == 1);
    // End points have only one neighbour but are border points of the chain.
    for (const int l : labels) CHECK(l == 0);
  } else {
    CHECK(dbscan.num_clusters() == 0);
    for (const int l : labels) CHECK(l == kNoise);
  }
}

TEST_CASE("DBSCAN min_points counts the point itself", "[dbscan]") {
  // Three points pairwise within eps: each has exactly 3 neighbours (itself included).
  const std::vector<Position> pts = {{0, 0}, {0.5, 0}, {0.25, 0.3}};
  const int min_points = GENERATE(2, 3, 4);
  Dbscan dbscan(DbscanParams{.eps = 1.0, .min_points = min_points});
  const auto labels = dbscan.Run(pts);
  CHECK(dbscan.num_clusters() == (min_points <= 3 ? 1 : 0));
  for (const int l : labels) CHECK(l == (min_points <= 3 ? 0 : kNoise));
}

TEST_CASE("DBSCAN border point joins its nearest core point's cluster", "[dbscan]") {
  // Core A at (0, 0) backed by three points 0.5 m behind it; core B at (1.6, 0) backed by three
  // points 0.5 m beyond it. A and B are 1.6 m apart, so never linked. The border point at
  // (x, 0) reaches only A and B (the backing points are >= 1.2 m away): itself + 2 < min_points 4,
  // while A and B have 5 neighbours and each backing point 4.
  const double x = GENERATE(0.7, 0.9);
  std::vector<Position> pts = {{0.0, 0.0}, {-0.5, 0.0}, {-0.5, 0.2}, {-0.5, -0.2},
                               {1.6, 0.0}, {2.1, 0.0},  {2.1, 0.2},  {2.1, -0.2}};
  pts.emplace_back(x, 0.0);
  Dbscan dbscan(DbscanParams{.eps = 1.0, .min_points = 4});
  const auto labels = dbscan.Run(pts);
  REQUIRE(dbscan.num_clusters() == 2);
  for (int i = 0; i < 4; ++i) CHECK(labels[i] == 0);
  for (int i = 4; i < 8; ++i) CHECK(labels[i] == 1);
  CHECK(labels[8] == (x < 0.8 ? 0 : 1));  // the nearer core wins
}

TEST_CASE("DBSCAN weighted core criterion", "[dbscan]") {
  const std::vector<Position> pts = {{0, 0},  {0.5, 0},  {0.25, 0.3},
                                     {10, 0}, {10.5, 0}, {10.2, 0.3}};
  const std::vector<double> w = {0.1, 0.1, 0.1, 1.0, 1.0, 1.0};
  Dbscan dbscan(DbscanParams{.eps = 1.0, .min_points = 3, .min_weight = 1.0});
  const auto labels = dbscan.Run(pts, w);
  REQUIRE(dbscan.num_clusters() == 1);
  CHECK(labels[0] == kNoise);
  CHECK(labels[3] == 0);
  // Without weights the light group forms a cluster too.
  dbscan.Run(pts);
  CHECK(dbscan.num_clusters() == 2);
  CHECK_THROWS_AS(dbscan.Run(pts, std::vector<double>(2, 1.0)), std::invalid_argument);
}

TEST_CASE("DBSCAN on empty input", "[dbscan]") {
  Dbscan dbscan;
  CHECK(dbscan.Run({}).empty());
  CHECK(dbscan.num_clusters() == 0);
}

TEST_CASE("DBSCAN matches a brute-force reference and is permutation invariant", "[dbscan]") {
  const std::uint64_t seed = GENERATE(range(1, 21));
  const bool snap = GENERATE(false, true);
  std::vector<Position> pts = RandomPoints(seed, 300, 20.0, snap);
  // Shifted across zero: index cells of negative coordinates, and (snapped) points exactly on
  // their edges, where flooring a negative coordinate differs from truncating it.
  const double offset = GENERATE(0.0, -10.0);
  for (Position& q : pts) q += Position(offset, offset);
  // One far outlier makes the points' rectangle too sparse for the dense index: the hash path.
  const bool sparse = GENERATE(false, true);
  if (sparse) pts.emplace_back(3.0e7, -2.0e7);
  const int n = static_cast<int>(pts.size());
  // Weighted: weights in eighths (every partial sum exact, so any summation order agrees with
  // the reference), and a min_weight that some points with min_points neighbours miss.
  const bool weighted = GENERATE(false, true);
  const DbscanParams params{.eps = 1.0, .min_points = 4, .min_weight = weighted ? 2.5 : 0.0};
  std::vector<double> weights(n);
  for (int i = 0; i < n; ++i) weights[i] = (1 + i % 5) / 8.0;
  Dbscan dbscan(params);
  std::vector<int> identity(n);
  std::iota(identity.begin(), identity.end(), 0);
  const auto labels_span = dbscan.Run(pts, weights);
  const std::vector<int> labels(labels_span.begin(), labels_span.end());

  int weight_misses = 0;
  const std::vector<int> comp = ReferenceLabels(pts, weights, params, &weight_misses);
  if (weighted) CHECK(weight_misses > 0);  // the weighted criterion decided some points
  const int nc = comp.empty() ? 0 : *std::max_element(comp.begin(), comp.end()) + 1;
  CHECK(dbscan.num_clusters() == nc);
  CHECK(Partition(labels, identity) == Partition(comp, identity));
  // Labels are numbered by first appearance in input order.
  int next = 0;
  for (const int l : labels) {
    if (l == kNoise) continue;
    CHECK(l <= next);
    if (l == next) ++next;
  }

  // Permuted input: same partition of point identities.
  std::vector<int> perm = identity;
  CounterRng rng(seed, RngPurpose::kTest, 1, 0);
  for (int i = n - 1; i > 0; --i)
    std::swap(perm[i], perm[static_cast<int>(rng.Uniform() * (i + 1))]);
  std::vector<Position> shuffled(n);
  std::vector<double> shuffled_weights(n);
  for (int i = 0; i < n; ++i) shuffled[i] = pts[perm[i]], shuffled_weights[i] = weights[perm[i]];
  const auto shuffled_labels = dbscan.Run(shuffled, shuffled_weights);
  CHECK(Partition(shuffled_labels, perm) == Partition(labels, identity));
}

TEST_CASE("DBSCAN labels do not depend on the OpenMP thread count", "[dbscan]") {
  const std::uint64_t seed = GENERATE(range(1, 6));
  const std::vector<Position> pts = RandomPoints(seed, 5000, 30.0, seed % 2 == 0);
  Dbscan dbscan;
  const int saved = omp_get_max_threads();
  omp_set_num_threads(1);
  const auto one = dbscan.Run(pts);
  const std::vector<int> labels_one(one.begin(), one.end());
  omp_set_num_threads(4);
  const auto four = dbscan.Run(pts);
  omp_set_num_threads(saved);
  CHECK(std::vector<int>(four.begin(), four.end()) == labels_one);
}

namespace {

using dualgrid::eval::CellRun;
using dualgrid::eval::PointCells;

// `pts` reordered cell by cell (cells in row-major order, input order within a cell, as the
// filter hands its particles over), with the cells of side `side` whose lower-left corner of cell
// (0, 0) is `origin`: a point on an edge between cells goes to the lower one.
PointCells GroupByCells(std::vector<Position>& pts, const Position& origin, double side) {
  const auto cell = [&](const Position& p) {
    const auto index = [&](double v) {
      const double u = v / side;
      const double f = std::floor(u);
      return static_cast<std::int64_t>(f == u ? f - 1.0 : f);  // an edge: the lower cell
    };
    return std::pair(index(p.y() - origin.y()), index(p.x() - origin.x()));
  };
  std::stable_sort(pts.begin(), pts.end(),
                   [&](const Position& a, const Position& b) { return cell(a) < cell(b); });
  PointCells cells{origin, side, {}};
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const auto [y, x] = cell(pts[i]);
    if (i == 0 || cell(pts[i - 1]) != std::pair(y, x))
      cells.runs.push_back({x, y, static_cast<int>(i)});
  }
  return cells;
}

}  // namespace

TEST_CASE("DBSCAN in given cells labels as Run does", "[dbscan]") {
  const std::uint64_t seed = GENERATE(range(1, 11));
  const bool snap = GENERATE(false, true);  // points on the 0.5 m lattice: on cell edges
  // 0.5: the filter's cells (whole cells core, reach 3); 0.26 (reach 4); 0.8: above
  // eps / sqrt(2), so no cell is core as a whole (reach 2).
  const double side = GENERATE(0.5, 0.26, 0.8);
  const int min_points = GENERATE(2, 4);
  std::vector<Position> pts = RandomPoints(seed, 400, 20.0, snap);
  for (Position& q : pts) q += Position(-10.0, -7.0);
  const Position origin = snap ? Position(-3.0, 1.5) : Position(-3.1, 1.37);
  const PointCells cells = GroupByCells(pts, origin, side);
  const DbscanParams params{.eps = 1.0, .min_points = min_points};
  Dbscan given(params), reference(params);
  const auto labels = given.RunInCells(pts, {}, cells);
  const std::vector<int> got(labels.begin(), labels.end());
  const auto expected = reference.Run(pts);
  CHECK(got == std::vector<int>(expected.begin(), expected.end()));
  CHECK(given.num_clusters() == reference.num_clusters());
  CHECK(reference.num_clusters() > 1);
  // Run after RunInCells on the same object: its own fine grid again.
  const auto again = given.Run(pts);
  CHECK(std::vector<int>(again.begin(), again.end()) == got);
}

TEST_CASE("DBSCAN in given cells joins components through the outer rings as brute force does",
          "[dbscan]") {
  // Vehicle-like blobs on the filter's 0.5 m cells (eps = 1 m: reach 3), 1 - 8 points per cell,
  // random gaps between blobs: blobs one to three cells apart join or not by their facing points
  // (the outer rings), which only the cells near another ring-1 component try. 6 blobs on a small
  // area (the rectangles' path) and 150 on a large one (more ring-1 components than the
  // rectangles take: every core cell tries the outer rings).
  const std::uint64_t seed = GENERATE(range(1, 11));
  const int blobs = GENERATE(6, 150);
  const double extent = blobs < 50 ? 8.0 : 60.0;
  CounterRng rng(seed, RngPurpose::kTest, 2, 0);
  std::vector<Position> pts;
  for (int b = 0; b < blobs; ++b) {
    const int x0 = static_cast<int>(rng.Uniform(0.0, extent / 0.5)),
              y0 = static_cast<int>(rng.Uniform(0.0, extent / 0.5));
    const int w = 1 + static_cast<int>(rng.Uniform(0.0, 5.0)),
              h = 1 + static_cast<int>(rng.Uniform(0.0, 3.0));
    for (int x = x0; x < x0 + w; ++x)
      for (int y = y0; y < y0 + h; ++y)
        for (int k = 1 + static_cast<int>(rng.Uniform(0.0, 8.0)); k > 0; --k)
          pts.emplace_back(0.5 * (x + rng.Uniform()), 0.5 * (y + rng.Uniform()));
  }
  const PointCells cells = GroupByCells(pts, Position::Zero(), 0.5);
  const DbscanParams params{.eps = 1.0, .min_points = 3};
  Dbscan dbscan(params);
  const auto labels = dbscan.RunInCells(pts, {}, cells);
  int weight_misses = 0;
  const std::vector<int> expected = ReferenceLabels(pts, {}, params, &weight_misses);
  std::vector<int> identity(pts.size());
  std::iota(identity.begin(), identity.end(), 0);
  CHECK(Partition(labels, identity) == Partition(expected, identity));
  CHECK(dbscan.num_clusters() == *std::max_element(expected.begin(), expected.end()) + 1);
  CHECK(dbscan.num_clusters() > 1);
}

TEST_CASE("DBSCAN in given cells notices a run's point outside its cell on each side", "[dbscan]") {
  // The lattice points grouped by 0.5 m cells; in a run of several points one point is moved
  // 2.5 m along one axis (the others stay inside), so that only the run's lowest or highest
  // coordinate leaves the cell: RunInCells must notice it and give Run's labels, which trusting
  // the cell (the moved point taken as core in its crowded cell, or unseen where it now lies)
  // would change.
  const std::uint64_t seed = GENERATE(range(1, 6));
  std::vector<Position> base = RandomPoints(seed, 400, 12.0, false);
  const PointCells cells = GroupByCells(base, Position::Zero(), 0.5);
  const Position moves[] = {{2.5, 0.0}, {-2.5, 0.0}, {0.0, 2.5}, {0.0, -2.5}};
  const int n = static_cast<int>(base.size());
  int tried = 0;
  for (std::size_t r = 0; r < cells.runs.size(); ++r) {
    const int first = cells.runs[r].first;
    const int last = r + 1 < cells.runs.size() ? cells.runs[r + 1].first : n;
    if (last - first < 3) continue;
    for (const Position& move : moves) {
      std::vector<Position> pts = base;
      pts[first + 1] += move;  // neither the run's first nor its last point
      Dbscan given({.eps = 1.0, .min_points = 3}), reference({.eps = 1.0, .min_points = 3});
      const auto got = given.RunInCells(pts, {}, cells);
      const auto expected = reference.Run(pts);
      CHECK(std::vector<int>(got.begin(), got.end()) ==
            std::vector<int>(expected.begin(), expected.end()));
      ++tried;
    }
  }
  CHECK(tried >= 40);
}

TEST_CASE("DBSCAN in given cells links points exactly eps apart three cells apart", "[dbscan]") {
  // Cells of 0.5 m: (0.5, 0.1) on the right edge of cell 0 and (1.5, 0.1) on the left edge of
  // cell 3 are exactly eps apart; and a pair slightly nearer each edge than the cells' slack.
  std::vector<Position> pts = {{0.5, 0.1}, {1.5, 0.1}, {0.5, 3.1}, {1.5, 3.1}};
  PointCells cells{Position::Zero(), 0.5, {{0, 0, 0}, {3, 0, 1}, {0, 6, 2}, {3, 6, 3}}};
  Dbscan dbscan({.eps = 1.0, .min_points = 2});
  const auto labels = dbscan.RunInCells(pts, {}, cells);
  CHECK(std::vector<int>(labels.begin(), labels.end()) == std::vector<int>{0, 0, 1, 1});
  // The same points over 0.5 m cells, one nudged past the slack of its cell: Run's result.
  pts[1] = Position(1.5 - 0.01, 0.1);
  const auto nudged = dbscan.RunInCells(pts, {}, cells);
  CHECK(std::vector<int>(nudged.begin(), nudged.end()) == std::vector<int>{0, 0, 1, 1});
  pts[1] = Position(1.5 + 0.01, 0.1);  // now beyond eps
  const auto apart = dbscan.RunInCells(pts, {}, cells);
  CHECK(std::vector<int>(apart.begin(), apart.end()) == std::vector<int>{kNoise, kNoise, 0, 0});

  // Cells slightly wider than eps / 2, points just outside them (within the slack): cells 3
  // apart hold points within eps (0.9995 m).
  const double side = 0.5002;
  const std::vector<Position> edge = {{1.0009 * side, 0.1}, {2.9991 * side, 0.1}};
  const auto slack = dbscan.RunInCells(edge, {}, {Position::Zero(), side, {{0, 0, 0}, {3, 0, 1}}});
  CHECK(std::vector<int>(slack.begin(), slack.end()) == std::vector<int>{0, 0});

  // Cells of 0.8 m (diagonal 1.13 m): two points of one cell 1.10 m apart are not neighbours.
  const std::vector<Position> wide = {{0.01, 0.01}, {0.79, 0.79}};
  const auto apart_in_cell = dbscan.RunInCells(wide, {}, {Position::Zero(), 0.8, {{0, 0, 0}}});
  CHECK(std::vector<int>(apart_in_cell.begin(), apart_in_cell.end()) ==
        std::vector<int>{kNoise, kNoise});
}

TEST_CASE("DBSCAN in given cells rejects malformed runs", "[dbscan]") {
  const std::vector<Position> pts = {{0.1, 0.1}, {0.2, 0.1}, {0.7, 0.1}};
  Dbscan dbscan;
  CHECK_THROWS_AS(dbscan.RunInCells(pts, {}, {Position::Zero(), 0.5, {{0, 0, 1}, {1, 0, 2}}}),
                  std::invalid_argument);  // not from 0
  CHECK_THROWS_AS(dbscan.RunInCells(pts, {}, {Position::Zero(), 0.5, {{0, 0, 0}, {1, 0, 0}}}),
                  std::invalid_argument);  // not rising
  CHECK_THROWS_AS(dbscan.RunInCells(pts, {}, {Position::Zero(), 0.5, {{0, 0, 0}, {1, 0, 3}}}),
                  std::invalid_argument);  // past the points
  CHECK_THROWS_AS(dbscan.RunInCells(pts, {}, {Position::Zero(), 0.5, {}}), std::invalid_argument);
  // A cell in two runs, a point outside its cell: Run's labels.
  const auto twice = dbscan.RunInCells(pts, {}, {Position::Zero(), 0.5, {{0, 0, 0}, {0, 0, 2}}});
  const std::vector<int> got(twice.begin(), twice.end());
  Dbscan reference;
  const auto expected = reference.Run(pts);
  CHECK(got == std::vector<int>(expected.begin(), expected.end()));
  const auto outside =
      dbscan.RunInCells(pts, {}, {Position::Zero(), 0.5, {{0, 0, 0}, {0, 1, 2}}});  // 0.7 in x
  CHECK(std::vector<int>(outside.begin(), outside.end()) ==
        std::vector<int>(expected.begin(), expected.end()));
}
