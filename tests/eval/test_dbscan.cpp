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

  // Brute-force reference, O(n^2): core flags, core components, border -> nearest core.
  std::vector<std::vector<int>> nb(n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      if ((pts[i] - pts[j]).norm() <= params.eps) nb[i].push_back(j);
  std::vector<bool> core(n);
  int weight_misses = 0;
  for (int i = 0; i < n; ++i) {
    double w = 0.0;
    for (const int j : nb[i]) w += weights[j];
    core[i] = static_cast<int>(nb[i].size()) >= params.min_points && w >= params.min_weight;
    weight_misses += static_cast<int>(nb[i].size()) >= params.min_points && !core[i];
  }
  if (weighted) CHECK(weight_misses > 0);  // the weighted criterion decided some points
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
