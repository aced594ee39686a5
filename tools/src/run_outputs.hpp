// The files a `dualgrid run` writes besides the ground truth and detections (docs/output.md):
// per-cycle clusters, per-vehicle weight traces, the particles behind a picture, and the results.
#pragma once

#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "dualgrid/cosim/pipeline.hpp"
#include "dualgrid/cosim/scoring.hpp"
#include "dualgrid/eval/aggregate.hpp"
#include "figures.hpp"
#include "output.hpp"

namespace dualgrid::tools {

/// clusters.csv: every cluster of every cycle with its role in the association.
class ClusterWriter {
 public:
  explicit ClusterWriter(const std::filesystem::path& path);
  /// The clusters of `scorer`'s last frame, for mode `mode`; `objects` as given to the scorer.
  /// Clusters are scored in the grid frame and written in the world frame.
  void Write(const sim::Frame& frame, const GridFrame& grid_frame, const std::string& mode,
             const cosim::ModeScorer& scorer, const std::vector<eval::TruthObject>& objects,
             const cosim::IdRegistry& ids);
  void Close() { out_.Close(); }

 private:
  OutputFile out_;
};

/// Weight traces of every vehicle in the grid (paper Fig. 4), from one filter's particles.
/// Only traces that can still become the focus are kept: the requested vehicle's, those of the
/// vehicles in the grid now, and the current leader's (most frames in the grid); a trace whose
/// vehicle has left the grid behind the leader is dropped, and that vehicle is no longer a
/// candidate (its trace would be incomplete). Memory stays bounded on long runs (the soak test
/// grew by 50 MB an hour keeping every vehicle's trace).
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

/// figures/particles_<mode>_t<time>.csv: every particle of filter `m` with its cell's P(dynamic).
void WriteParticles(const cosim::Pipeline& pipeline, std::size_t m,
                    const cosim::GridSnapshot& snapshot, const std::filesystem::path& path);

/// objects.csv: one row per (mode, object ever in the grid); with `categories` (object name ->
/// category: annotated data) a last column `category`.
void WriteObjects(const std::vector<std::string>& modes,
                  const std::vector<eval::ScenarioMetrics>& metrics, const cosim::IdRegistry& ids,
                  const std::filesystem::path& path,
                  const std::map<std::string, std::string>* categories = nullptr);

/// weights.csv of one vehicle's trace.
void WriteWeights(const WeightTrace& trace, const std::string& object,
                  const std::filesystem::path& path);

/// table.md, table.csv and table.json.
void WriteTables(const eval::ComparisonTable& table, const std::filesystem::path& dir);

/// Notes for the table: the objects that were in the grid but too briefly to be scored.
std::vector<std::string> UnscoredNotes(const std::vector<eval::ScenarioMetrics>& metrics,
                                       const cosim::IdRegistry& ids, int min_frames_in_grid);

}  // namespace dualgrid::tools
