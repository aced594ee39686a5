// Particle weights on the vehicles in the grid over a run (paper Fig. 4): weights.csv and
// figures/weights.png are drawn from them.
#pragma once

#include <map>
#include <set>
#include <string>
#include <vector>

#include "dualgrid/cosim/pipeline.hpp"

namespace dualgrid::outputs {

/// Particle weights on one object over time (paper Fig. 4). The filter normalises both weights
/// per cell, so their sums over an object are equal; what differs is *which* particles carry
/// them: the shares are the fraction of each weight held by particles whose velocity is within
/// `kGoodVelocity` of the object's true velocity.
struct WeightTrace {
  static constexpr double kGoodVelocity = 2.0;  ///< [m/s]
  std::vector<double> time, w_position, w_velocity, weight;
  std::vector<double> position_share, velocity_share;
  /// Share of the object's detections whose |compensated Doppler| is below half its speed.
  std::vector<double> tangential_share;
};

/// Weight traces of every vehicle in the grid (paper Fig. 4), from one filter's particles.
/// Only traces that can still become the focus are kept: the requested vehicle's, those of the
/// vehicles in the grid now, and the current leader's (most frames in the grid); a trace whose
/// vehicle has left the grid behind the leader is dropped, and that vehicle is no longer a
/// candidate (its trace would be incomplete). Memory stays bounded on long runs.
struct WeightTraces {
  explicit WeightTraces(std::string requested) : requested(std::move(requested)) {}
  std::string requested;  ///< the scenario's focus object, may be empty
  std::map<std::string, WeightTrace> by_vehicle;
  std::map<std::string, int> frames_in_grid;
  std::set<std::string> dropped;
  /// Adds the current step of `pipeline` for filter `mode`.
  void Add(const cosim::Pipeline& pipeline, std::size_t mode);
  /// The requested focus object if it was in the grid, else the candidate longest in the grid;
  /// empty when no vehicle was.
  std::string Focus() const;
};

}  // namespace dualgrid::outputs
