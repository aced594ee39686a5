#include "dualgrid/eval/association.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "dualgrid/core/validation.hpp"

namespace dualgrid::eval {

bool AssociationParams::IsValid(std::string* error) const {
  FieldCheck c;
  c.NonNegative("box_margin", box_margin, "m");
  c.Positive("center_gate", center_gate, "m");
  return c.Done(error);
}

void to_json(nlohmann::json& j, const AssociationParams& p) {
  j = {{"box_margin", p.box_margin}, {"center_gate", p.center_gate}};
}

bool InGate(const Position& p, const TruthObject& object, const AssociationParams& params) {
  const OrientedBox& box = object.box;
  const Vector2 d = Rotation(box.yaw).transpose() * (p - box.center);
  const double half_l = 0.5 * box.length, half_w = 0.5 * box.width;
  if (std::abs(d.x()) <= half_l + params.box_margin &&
      std::abs(d.y()) <= half_w + params.box_margin)
    return true;
  const double a = params.center_gate + half_l, b = params.center_gate;
  return (d.x() / a) * (d.x() / a) + (d.y() / b) * (d.y() / b) <= 1.0;
}

std::vector<int> SolveAssignment(std::span<const double> cost, int rows, int cols) {
  if (rows < 0 || cols < 0 || cost.size() != static_cast<std::size_t>(rows) * cols)
    throw std::invalid_argument("SolveAssignment: cost has " + std::to_string(cost.size()) +
                                " entries for " + std::to_string(rows) + "x" +
                                std::to_string(cols));
  std::vector<int> result(rows, -1);
  if (rows == 0 || cols == 0) return result;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  double max_cost = 0.0;
  for (const double c : cost) {
    if (std::isnan(c) || c < 0.0 || c == -kInf)
      throw std::invalid_argument("SolveAssignment: costs must be >= 0 or +infinity");
    if (c != kInf) max_cost = std::max(max_cost, c);
  }
  // Forbidden and padding entries get a cost `big` exceeding any sum of real costs over a
  // matching, so an optimum first maximises the number of real (finite) pairs.
  const int n = std::max(rows, cols);
  const double big = (std::min(rows, cols) + 1) * (max_cost + 1.0);
  auto a = [&](int i, int j) {  // 1-based, square, padded
    if (i > rows || j > cols) return big;
    const double c = cost[static_cast<std::size_t>(i - 1) * cols + (j - 1)];
    return c == kInf ? big : c;
  };
  // Hungarian algorithm with potentials (Kuhn-Munkres, O(n^3)).
  std::vector<double> u(n + 1, 0.0), v(n + 1, 0.0), minv(n + 1);
  std::vector<int> p(n + 1, 0), way(n + 1, 0);
  std::vector<char> used(n + 1);
  for (int i = 1; i <= n; ++i) {
    p[0] = i;
    int j0 = 0;
    std::fill(minv.begin(), minv.end(), kInf);
    std::fill(used.begin(), used.end(), 0);
    do {
      used[j0] = 1;
      const int i0 = p[j0];
      double delta = kInf;
      int j1 = 0;
      for (int j = 1; j <= n; ++j) {
        if (used[j]) continue;
        const double cur = a(i0, j) - u[i0] - v[j];
        if (cur < minv[j]) {
          minv[j] = cur;
          way[j] = j0;
        }
        if (minv[j] < delta) {
          delta = minv[j];
          j1 = j;
        }
      }
      for (int j = 0; j <= n; ++j) {
        if (used[j]) {
          u[p[j]] += delta;
          v[j] -= delta;
        } else {
          minv[j] -= delta;
        }
      }
      j0 = j1;
    } while (p[j0] != 0);
    do {
      const int j1 = way[j0];
      p[j0] = p[j1];
      j0 = j1;
    } while (j0 != 0);
  }
  for (int j = 1; j <= cols; ++j) {
    const int i = p[j];
    if (i >= 1 && i <= rows && cost[static_cast<std::size_t>(i - 1) * cols + (j - 1)] != kInf)
      result[i - 1] = j - 1;
  }
  return result;
}

AssociationResult Associate(std::span<const Cluster> clusters, std::span<const TruthObject> objects,
                            const AssociationParams& params) {
  std::string error;
  if (!params.IsValid(&error)) throw std::invalid_argument("AssociationParams: " + error);
  const int nc = static_cast<int>(clusters.size()), no = static_cast<int>(objects.size());
  std::vector<double> cost(static_cast<std::size_t>(nc) * no,
                           std::numeric_limits<double>::infinity());
  std::vector<char> gated(nc, 0);
  for (int c = 0; c < nc; ++c) {
    for (int o = 0; o < no; ++o) {
      if (!InGate(clusters[c].position, objects[o], params)) continue;
      cost[static_cast<std::size_t>(c) * no + o] =
          (clusters[c].position - objects[o].box.center).norm();
      gated[c] = 1;
    }
  }
  AssociationResult r;
  r.object_of_cluster = SolveAssignment(cost, nc, no);
  r.cluster_of_object.assign(no, -1);
  r.role.resize(nc);
  for (int c = 0; c < nc; ++c) {
    const int o = r.object_of_cluster[c];
    if (o >= 0) {
      r.cluster_of_object[o] = c;
      r.role[c] = ClusterRole::kMatched;
      ++r.num_matched;
    } else if (gated[c]) {
      r.role[c] = ClusterRole::kDuplicate;
      ++r.num_duplicate;
    } else {
      r.role[c] = ClusterRole::kFalse;
      ++r.num_false;
    }
  }
  return r;
}

}  // namespace dualgrid::eval
