#include <cmath>
#include <limits>
#include <vector>

#include <catch2/catch.hpp>

#include "dualgrid/core/random.hpp"
#include "dualgrid/eval/association.hpp"

using dualgrid::CounterRng;
using dualgrid::OrientedBox;
using dualgrid::Position;
using dualgrid::RngPurpose;
using dualgrid::Vector2;
using dualgrid::eval::Associate;
using dualgrid::eval::AssociationParams;
using dualgrid::eval::Cluster;
using dualgrid::eval::ClusterRole;
using dualgrid::eval::InGate;
using dualgrid::eval::SolveAssignment;
using dualgrid::eval::TruthObject;

namespace {

TruthObject Car(int id, Position center, double yaw, double length = 4.0, double width = 2.0) {
  TruthObject o;
  o.id = id;
  o.box = OrientedBox{center, yaw, length, width};
  o.in_grid = o.in_coverage = true;
  return o;
}

Cluster At(Position p) {
  Cluster c;
  c.position = p;
  c.size = 10;
  c.weight = 1.0;
  return c;
}

constexpr double kTiny = 1e-6;

}  // namespace

TEST_CASE("Association params validation names the field", "[association]") {
  std::string error;
  CHECK(AssociationParams{}.IsValid(&error));
  CHECK_FALSE(AssociationParams{.box_margin = -0.1}.IsValid(&error));
  CHECK(error.find("box_margin") != std::string::npos);
  CHECK_FALSE(AssociationParams{.center_gate = 0.0}.IsValid(&error));
  CHECK(error.find("center_gate") != std::string::npos);
}

TEST_CASE("Gate edges, any pose", "[association]") {
  const double yaw = GENERATE(0.0, 0.3, 1.5707963267948966, -2.5, 3.0);
  const Position center = GENERATE(Position(0.0, 0.0), Position(-120.5, 37.25));
  const TruthObject car = Car(1, center, yaw);  // L = 4, W = 2
  const AssociationParams params;               // margin 1.0, centre gate 2.5
  auto world = [&](double along, double left) {
    return Position(car.box.center + dualgrid::Rotation(yaw) * Vector2(along, left));
  };
  // Grown box corner (L/2 + 1, W/2 + 1) = (3, 2) lies outside the ellipse
  // ((3/4.5)^2 + (2/2.5)^2 = 1.08), so this probes the box gate alone.
  CHECK(InGate(world(3.0 - kTiny, 2.0 - kTiny), car, params));
  CHECK_FALSE(InGate(world(3.0 + kTiny, 2.0 + kTiny), car, params));
  CHECK(InGate(world(-3.0 + kTiny, -2.0 + kTiny), car, params));
  CHECK_FALSE(InGate(world(-3.0 - kTiny, -2.0 - kTiny), car, params));
  // Ellipse semi-axes: 2.5 + L/2 = 4.5 along the heading, 2.5 across; both beyond the box gate.
  CHECK(InGate(world(4.5 - kTiny, 0.0), car, params));
  CHECK_FALSE(InGate(world(4.5 + kTiny, 0.0), car, params));
  CHECK(InGate(world(-4.5 + kTiny, 0.0), car, params));
  CHECK_FALSE(InGate(world(-4.5 - kTiny, 0.0), car, params));
  CHECK(InGate(world(0.0, 2.5 - kTiny), car, params));
  CHECK_FALSE(InGate(world(0.0, 2.5 + kTiny), car, params));
  CHECK(InGate(world(0.0, -2.5 + kTiny), car, params));
  CHECK_FALSE(InGate(world(0.0, -2.5 - kTiny), car, params));
}

TEST_CASE("Assignment maximises matches before distance (not greedy)", "[association]") {
  // Two cars in adjacent lanes 3.5 m apart. Cluster A sits between them (1.5 m from car 1, 2.0 m
  // from car 2, gated to both); cluster B is 3.5 m ahead of car 1 and gated only to it. Greedy
  // nearest-first would give A -> car 1 and leave car 2 unmatched; the optimum matches both.
  const std::vector<TruthObject> cars = {Car(1, {0.0, 0.0}, 0.0, 4.5, 1.8),
                                         Car(2, {0.0, 3.5}, 0.0, 4.5, 1.8)};
  const std::vector<Cluster> clusters = {At({0.0, 1.5}), At({3.5, 0.0})};
  REQUIRE(InGate(clusters[0].position, cars[0], {}));
  REQUIRE(InGate(clusters[0].position, cars[1], {}));
  REQUIRE(InGate(clusters[1].position, cars[0], {}));
  REQUIRE_FALSE(InGate(clusters[1].position, cars[1], {}));
  const auto r = Associate(clusters, cars);
  CHECK(r.object_of_cluster == std::vector<int>{1, 0});
  CHECK(r.cluster_of_object == std::vector<int>{1, 0});
  CHECK(r.num_matched == 2);
  CHECK(r.num_duplicate == 0);
  CHECK(r.num_false == 0);
}

TEST_CASE("Split truck gives a duplicate, a cluster off every vehicle is false", "[association]") {
  const std::vector<TruthObject> objects = {Car(7, {0.0, 0.0}, 0.0, 12.0, 2.5),
                                            Car(8, {0.0, 30.0}, 0.0)};
  // Front and rear halves of the truck (3.2 m and 3.0 m from its centre), one cluster 15 m off.
  const std::vector<Cluster> clusters = {At({3.2, 0.1}), At({-3.0, -0.2}), At({0.0, 15.0})};
  const auto r = Associate(clusters, objects);
  CHECK(r.object_of_cluster == std::vector<int>{-1, 0, -1});  // the nearer half wins
  CHECK(r.role[0] == ClusterRole::kDuplicate);
  CHECK(r.role[1] == ClusterRole::kMatched);
  CHECK(r.role[2] == ClusterRole::kFalse);
  CHECK(r.cluster_of_object == std::vector<int>{1, -1});
  CHECK(r.num_matched == 1);
  CHECK(r.num_duplicate == 1);
  CHECK(r.num_false == 1);
}

TEST_CASE("SolveAssignment equals brute force on random gated matrices", "[association]") {
  const std::uint64_t seed = GENERATE(range(1, 41));
  CounterRng rng(seed, RngPurpose::kTest, 0, 0);
  const int rows = 1 + static_cast<int>(rng.Uniform() * 5);
  const int cols = 1 + static_cast<int>(rng.Uniform() * 5);
  constexpr double kInf = std::numeric_limits<double>::infinity();
  std::vector<double> cost(rows * cols);
  for (double& c : cost) c = rng.Uniform() < 0.4 ? kInf : rng.Uniform(0.0, 10.0);

  // Brute force over all partial injective assignments: best (matches desc, cost asc).
  int best_matches = -1;
  double best_cost = kInf;
  std::vector<int> col_of_row(rows, -1);
  std::vector<bool> used(cols, false);
  auto recurse = [&](auto&& self, int r, int matches, double total) -> void {
    if (r == rows) {
      if (matches > best_matches || (matches == best_matches && total < best_cost)) {
        best_matches = matches;
        best_cost = total;
      }
      return;
    }
    self(self, r + 1, matches, total);
    for (int c = 0; c < cols; ++c) {
      if (used[c] || cost[r * cols + c] == kInf) continue;
      used[c] = true;
      self(self, r + 1, matches + 1, total + cost[r * cols + c]);
      used[c] = false;
    }
  };
  recurse(recurse, 0, 0, 0.0);

  const std::vector<int> result = SolveAssignment(cost, rows, cols);
  REQUIRE(static_cast<int>(result.size()) == rows);
  int matches = 0;
  double total = 0.0;
  std::vector<bool> taken(cols, false);
  for (int r = 0; r < rows; ++r) {
    if (result[r] < 0) continue;
    REQUIRE(result[r] < cols);
    CHECK_FALSE(taken[result[r]]);
    taken[result[r]] = true;
    REQUIRE(cost[r * cols + result[r]] != kInf);
    ++matches;
    total += cost[r * cols + result[r]];
  }
  CHECK(matches == best_matches);
  CHECK(total == Approx(best_cost).margin(1e-9));
}

TEST_CASE("SolveAssignment rejects bad input", "[association]") {
  CHECK_THROWS_AS(SolveAssignment(std::vector<double>(3, 1.0), 2, 2), std::invalid_argument);
  CHECK_THROWS_AS(SolveAssignment(std::vector<double>{-1.0}, 1, 1), std::invalid_argument);
  CHECK(SolveAssignment({}, 0, 3).empty());
  CHECK(SolveAssignment({}, 2, 0) == std::vector<int>{-1, -1});
}
