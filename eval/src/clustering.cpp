#include "dualgrid/eval/clustering.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace dualgrid::eval {

ParticleClusterer::ParticleClusterer(const DbscanParams& params, double min_cluster_weight)
    : dbscan_(params), min_cluster_weight_(min_cluster_weight) {
  if (!(min_cluster_weight >= 0.0 && std::isfinite(min_cluster_weight)))
    throw std::invalid_argument("ParticleClusterer: min_cluster_weight must be finite and >= 0");
}

std::vector<Cluster> ParticleClusterer::Run(std::span<const WeightedParticle> particles) {
  const int n = static_cast<int>(particles.size());
  positions_.resize(n);
  weights_.resize(n);
  for (int i = 0; i < n; ++i) {
    const WeightedParticle& p = particles[i];
    if (!(std::isfinite(p.weight) && p.weight >= 0.0))
      throw std::invalid_argument("ParticleClusterer: particle " + std::to_string(i) +
                                  " has weight " + std::to_string(p.weight) + " (need >= 0)");
    if (!p.velocity.allFinite())
      throw std::invalid_argument("ParticleClusterer: particle " + std::to_string(i) +
                                  " has a non-finite velocity");
    positions_[i] = p.position;
    weights_[i] = p.weight;
  }
  const std::span<const int> labels = dbscan_.Run(positions_, weights_);
  labels_.assign(labels.begin(), labels.end());

  const int k = dbscan_.num_clusters();
  std::vector<Cluster> clusters(k);
  // Unweighted sums kept alongside for the zero-weight fallback.
  std::vector<Position> plain_position(k, Position::Zero());
  std::vector<Velocity> plain_velocity(k, Velocity::Zero());
  for (Cluster& c : clusters) {
    c.min = Position::Constant(std::numeric_limits<double>::infinity());
    c.max = -c.min;
  }
  for (int i = 0; i < n; ++i) {
    if (labels_[i] == kNoise) continue;
    const WeightedParticle& p = particles[i];
    Cluster& c = clusters[labels_[i]];
    c.position += p.weight * p.position;
    c.velocity += p.weight * p.velocity;
    c.weight += p.weight;
    ++c.size;
    c.min = c.min.cwiseMin(p.position);
    c.max = c.max.cwiseMax(p.position);
    plain_position[labels_[i]] += p.position;
    plain_velocity[labels_[i]] += p.velocity;
  }
  for (int c = 0; c < k; ++c) {
    Cluster& cl = clusters[c];
    if (cl.weight > 0.0) {
      cl.position /= cl.weight;
      cl.velocity /= cl.weight;
    } else {
      cl.position = plain_position[c] / cl.size;
      cl.velocity = plain_velocity[c] / cl.size;
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
