#include "dualgrid/eval/dbscan.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace dualgrid::eval {

namespace {

std::uint64_t PackKey(std::int64_t ix, std::int64_t iy) {
  // Two's-complement truncation to 32 bits is injective for |index| < 2^31 cells.
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(ix)) << 32) |
         static_cast<std::uint32_t>(iy);
}

// Strict order used to break distance ties between core points: lexicographic (x, y).
bool LexLess(const Position& a, const Position& b) {
  return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
}

}  // namespace

bool DbscanParams::IsValid(std::string* error) const {
  auto fail = [&](const char* msg) {
    if (error != nullptr) *error = msg;
    return false;
  };
  if (!(std::isfinite(eps) && eps > 0.0)) return fail("eps must be finite and > 0");
  if (min_points < 1) return fail("min_points must be >= 1");
  if (!(std::isfinite(min_weight) && min_weight >= 0.0))
    return fail("min_weight must be finite and >= 0");
  return true;
}

void to_json(nlohmann::json& j, const DbscanParams& p) {
  j = {{"eps", p.eps}, {"min_points", p.min_points}, {"min_weight", p.min_weight}};
}

Dbscan::Dbscan(const DbscanParams& params) : params_(params) {
  std::string error;
  if (!params_.IsValid(&error)) throw std::invalid_argument("DbscanParams: " + error);
  inv_eps_ = 1.0 / params_.eps;
}

template <typename F>
void Dbscan::ForEachNearBucket(const Position& p, F&& f) const {
  const auto ix = static_cast<std::int64_t>(std::floor(p.x() * inv_eps_));
  const auto iy = static_cast<std::int64_t>(std::floor(p.y() * inv_eps_));
  for (std::int64_t dx = -1; dx <= 1; ++dx) {
    for (std::int64_t dy = -1; dy <= 1; ++dy) {
      const auto it = bucket_of_key_.find(PackKey(ix + dx, iy + dy));
      if (it != bucket_of_key_.end() && !f(it->second)) return;
    }
  }
}

template <typename F>
void Dbscan::ForEachNeighbour(std::span<const Position> points, int i, F&& f) const {
  const double eps2 = params_.eps * params_.eps;
  const Position& p = points[i];
  ForEachNearBucket(p, [&](int b) {
    for (int s = start_[b]; s < start_[b + 1]; ++s) {
      const int j = sorted_[s];
      if ((points[j] - p).squaredNorm() <= eps2 && !f(j)) return false;
    }
    return true;
  });
}

std::span<const int> Dbscan::Run(std::span<const Position> points,
                                 std::span<const double> weights) {
  const int n = static_cast<int>(points.size());
  if (!weights.empty() && weights.size() != points.size())
    throw std::invalid_argument("Dbscan::Run: " + std::to_string(weights.size()) + " weights for " +
                                std::to_string(points.size()) + " points");
  for (int i = 0; i < n; ++i) {
    if (!points[i].allFinite())
      throw std::invalid_argument("Dbscan::Run: point " + std::to_string(i) + " is not finite");
  }

  // Spatial hash with cell size eps: every neighbour lies in the 3x3 block around a point's cell.
  bucket_of_key_.clear();
  key_.resize(n);
  bucket_.resize(n);
  start_.clear();
  for (int i = 0; i < n; ++i) {
    key_[i] = PackKey(static_cast<std::int64_t>(std::floor(points[i].x() * inv_eps_)),
                      static_cast<std::int64_t>(std::floor(points[i].y() * inv_eps_)));
    const auto [it, inserted] =
        bucket_of_key_.try_emplace(key_[i], static_cast<int>(bucket_of_key_.size()));
    bucket_[i] = it->second;
  }
  const int num_buckets = static_cast<int>(bucket_of_key_.size());
  start_.assign(num_buckets + 1, 0);
  for (int i = 0; i < n; ++i) ++start_[bucket_[i] + 1];
  for (int b = 0; b < num_buckets; ++b) start_[b + 1] += start_[b];
  sorted_.resize(n);
  {
    // Counting sort keeps input order inside each bucket; component_ is borrowed as the cursor.
    component_.assign(start_.begin(), start_.end() - 1);
    for (int i = 0; i < n; ++i) sorted_[component_[bucket_[i]]++] = i;
  }

  // Core points. Independent per point, so parallel; stops counting once both criteria hold.
  core_.assign(n, 0);
  const bool use_weights = !weights.empty() && params_.min_weight > 0.0;
#pragma omp parallel for schedule(dynamic, 256)
  for (int i = 0; i < n; ++i) {
    int count = 0;
    double weight = 0.0;
    ForEachNeighbour(points, i, [&](int j) {
      ++count;
      if (use_weights) weight += weights[j];
      const bool done =
          count >= params_.min_points && (!use_weights || weight >= params_.min_weight);
      if (done) core_[i] = 1;
      return !done;
    });
  }

  // Clusters are the connected components of the core graph (order independent). The search
  // runs over a second index holding only unvisited core points: a point leaves it when it is
  // reached, so dense clusters are not rescanned by every member (O(n * k) -> near O(n)).
  const double eps2 = params_.eps * params_.eps;
  core_start_.assign(num_buckets + 1, 0);
  core_live_.assign(num_buckets, 0);
  for (int i = 0; i < n; ++i) core_start_[bucket_[i] + 1] += core_[i];
  for (int b = 0; b < num_buckets; ++b) core_start_[b + 1] += core_start_[b];
  core_sorted_.resize(core_start_[num_buckets]);
  slot_.assign(n, -1);
  for (const int i : sorted_) {  // bucket order, input order within a bucket
    if (!core_[i]) continue;
    const int b = bucket_[i];
    slot_[i] = core_start_[b] + core_live_[b]++;
    core_sorted_[slot_[i]] = i;
  }
  auto remove_core = [&](int i) {  // swap-remove i from its bucket's live range
    const int b = bucket_[i];
    const int last = core_start_[b] + --core_live_[b];
    const int moved = core_sorted_[last];
    core_sorted_[slot_[i]] = moved;
    slot_[moved] = slot_[i];
    core_sorted_[last] = i;
    slot_[i] = last;
  };
  component_.assign(n, kNoise);
  int num_components = 0;
  for (int seed = 0; seed < n; ++seed) {
    if (!core_[seed] || component_[seed] != kNoise) continue;
    const int c = num_components++;
    component_[seed] = c;
    remove_core(seed);
    stack_.clear();
    stack_.push_back(seed);
    while (!stack_.empty()) {
      const int i = stack_.back();
      stack_.pop_back();
      const Position& p = points[i];
      ForEachNearBucket(p, [&](int b) {
        for (int s = core_start_[b]; s < core_start_[b] + core_live_[b];) {
          const int j = core_sorted_[s];
          if ((points[j] - p).squaredNorm() <= eps2) {
            component_[j] = c;
            stack_.push_back(j);
            remove_core(j);  // slot s now holds another live point (or the range shrank)
          } else {
            ++s;
          }
        }
        return true;
      });
    }
  }

  // Border points join their nearest core neighbour's cluster (see class comment for ties).
#pragma omp parallel for schedule(dynamic, 256)
  for (int i = 0; i < n; ++i) {
    if (core_[i]) continue;
    double best_d2 = std::numeric_limits<double>::infinity();
    int best = -1;
    ForEachNeighbour(points, i, [&](int j) {
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
