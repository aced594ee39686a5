// Particle weights on the vehicles in the grid over a run (paper Fig. 4): weights.csv and
// figures/weights.png are drawn from them.
#pragma once

#include <map>
#include <set>
#include <string>
#include <vector>

#include "dualgrid/core/types.hpp"
#include "dualgrid/cosim/pipeline.hpp"
#include "dualgrid/filter/particles.hpp"

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

/// Weight sums of the particles inside one box (paper Fig. 4): all three weights, and the position
/// and velocity weights of the particles whose velocity is within WeightTrace::kGoodVelocity of
/// the box's.
struct BoxWeights {
  double w_position = 0.0, w_velocity = 0.0, weight = 0.0;
  double w_position_good = 0.0, w_velocity_good = 0.0;
};

/// A particle set cut into runs of kRun consecutive indices with each run's axis-aligned bounds,
/// so that a box's sums read only the runs that can hold a particle inside it. Building is one
/// pass over the particles; Sum is O(runs + particles of the runs overlapping the box), cheap
/// where the set is roughly sorted by position (the filter's particles are, by cell). Keeps a
/// reference to `particles`, which must outlive it unchanged.
class ParticleRuns {
 public:
  static constexpr std::size_t kRun = 16;  ///< particles per run
  explicit ParticleRuns(const filter::ParticleSet& particles);
  /// The sums over the particles inside `box` (within its axis-aligned bounds grown by 1e-6 m and
  /// BoxTest::Contains; same frame as the particles), added in increasing index order: the same
  /// bits as a scan of every particle. `velocity` [m/s] is the box's, compared with each
  /// particle's for the "good" shares.
  BoxWeights Sum(const OrientedBox& box, const Velocity& velocity) const;

 private:
  const filter::ParticleSet& p_;
  std::vector<double> bounds_;  // per run: lowest x, highest x, lowest y, highest y [m]
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
