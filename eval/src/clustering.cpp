#include "dualgrid/eval/clustering.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace dualgrid::eval {

ParticleClusterer::ParticleClusterer(const DbscanParams& params, double min_cluster_weight)
    : dbscan_(params), min_cluster_weight_(min_cluster_weight) {
  if (!(min_cluster_weight >= 0.0 && std::isfinite(min_cluster_weight)))
    throw std::invalid_argument("ParticleClusterer: min_cluster_weight must be finite and >= 0");
}

void ParticleClusterer::PlainMeans(std::span<const WeightedParticle> particles, int label,
                                   Cluster& c) const {
  Position position = Position::Zero();
  Velocity velocity = Velocity::Zero();
  for (std::size_t i = 0; i < particles.size(); ++i) {
    if (labels_[i] != label) continue;
    position += particles[i].position;
    velocity += particles[i].velocity;
  }
  c.position = position / c.size;
  c.velocity = velocity / c.size;
}

std::vector<Cluster> ParticleClusterer::Run(std::span<const WeightedParticle> particles) {
  TakeParticles(particles);
  return Clusters(particles, dbscan_.Run(positions_, weights_));
}

std::vector<Cluster> ParticleClusterer::Run(std::span<const WeightedParticle> particles,
                                            const PointCells& cells) {
  TakeParticles(particles);
  return Clusters(particles, dbscan_.RunInCells(positions_, weights_, cells));
}

void ParticleClusterer::TakeParticles(std::span<const WeightedParticle> particles) {
  const int n = static_cast<int>(particles.size());
  positions_.resize(n);
  weights_.resize(n);
  // Copy first, checking without a branch per particle (finite and >= 0 is [0, max], which NaN
  // fails); only a bad set is walked again to name its first bad particle.
  constexpr double kMax = std::numeric_limits<double>::max();
  bool ok = true;
  for (int i = 0; i < n; ++i) {
    const WeightedParticle& p = particles[i];
    ok &= (p.weight >= 0.0) & (p.weight <= kMax) & (std::abs(p.velocity.x()) <= kMax) &
          (std::abs(p.velocity.y()) <= kMax);
    positions_[i] = p.position;
    weights_[i] = p.weight;
  }
  if (ok) return;
  for (int i = 0; i < n; ++i) {
    const WeightedParticle& p = particles[i];
    if (!(std::isfinite(p.weight) && p.weight >= 0.0))
      throw std::invalid_argument("ParticleClusterer: particle " + std::to_string(i) +
                                  " has weight " + std::to_string(p.weight) + " (need >= 0)");
    if (!p.velocity.allFinite())
      throw std::invalid_argument("ParticleClusterer: particle " + std::to_string(i) +
                                  " has a non-finite velocity");
  }
}

std::vector<Cluster> ParticleClusterer::Clusters(std::span<const WeightedParticle> particles,
                                                 std::span<const int> labels) {
  const int n = static_cast<int>(particles.size());
  labels_.assign(labels.begin(), labels.end());

  const int k = dbscan_.num_clusters();
  std::vector<Cluster> clusters(k);
  for (Cluster& c : clusters) {
    c.min = Position::Constant(std::numeric_limits<double>::infinity());
    c.max = -c.min;
  }
  // Runs of one label (the filter hands its particles over cell by cell, so a cluster's come in
  // long runs) are summed in locals: the same additions in the same order as into the cluster.
  for (int i = 0; i < n;) {
    const int label = labels_[i];
    if (label == kNoise) {
      ++i;
      continue;
    }
    Cluster& c = clusters[label];
    Position position = c.position, lo = c.min, hi = c.max;
    Velocity velocity = c.velocity;
    double weight = c.weight;
    int size = c.size;
    for (; i < n && labels_[i] == label; ++i) {
      const WeightedParticle& p = particles[i];
      position += p.weight * p.position;
      velocity += p.weight * p.velocity;
      weight += p.weight;
      ++size;
      lo = lo.cwiseMin(p.position);
      hi = hi.cwiseMax(p.position);
    }
    c.position = position;
    c.velocity = velocity;
    c.weight = weight;
    c.size = size;
    c.min = lo;
    c.max = hi;
  }
  for (int c = 0; c < k; ++c) {
    Cluster& cl = clusters[c];
    if (cl.weight > 0.0) {
      cl.position /= cl.weight;
      cl.velocity /= cl.weight;
    } else {
      PlainMeans(particles, c, cl);
    }
  }
  if (min_cluster_weight_ > 0.0) {
    // Drop light clusters and renumber the labels of the kept ones, order preserved.
    std::vector<int> new_label(k, kNoise);
    std::vector<Cluster> kept;
    for (int c = 0; c < k; ++c) {
      if (clusters[c].weight < min_cluster_weight_) continue;
      new_label[c] = static_cast<int>(kept.size());
      kept.push_back(clusters[c]);
    }
    for (int& l : labels_)
      if (l != kNoise) l = new_label[l];
    return kept;
  }
  return clusters;
}

}  // namespace dualgrid::eval
