// In-process SUMO (libsumo) driven by a ScenarioSpec.
//
// libsumo holds one simulation per process in global state, so at most one SumoSimulation may be
// alive at a time (a second constructor throws). Run several scenarios or seeds in separate
// processes (`dualgrid experiment` does).
#pragma once

#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <optional>

#include "dualgrid/sim/auto_ego.hpp"
#include "dualgrid/sim/ground_truth.hpp"
#include "dualgrid/sim/scenario.hpp"
#include "dualgrid/sim/sumo_additional.hpp"

namespace dualgrid::sim {

/// Where the built SUMO networks were found, and why there.
struct NetworkDirLocation {
  std::filesystem::path dir;
  /// "DUALGRID_NETWORK_DIR" (the environment), "installed" (share/dualgrid/networks beside the
  /// program), "package" (the installed package's, compiled into a find_package(dualgrid)
  /// consumer), "build tree" (the build's networks/ folder, compiled in), or "none".
  std::string source;
};
/// The first of: the environment variable DUALGRID_NETWORK_DIR; `PREFIX/share/dualgrid/networks`
/// where PREFIX is the parent of the folder holding `anchor` (the running program by default,
/// /proc/self/exe: an installed bin/dualgrid finds its own tree wherever it was moved);
/// `package_dir` when given (then nothing else is looked at: a consumer of the installed package
/// never uses a build tree); the build tree's networks/ folder compiled into this library. Only
/// folders that exist count, except the environment variable and `package_dir` (explicit
/// choices: a missing one is named by the error of the first network looked up in it); source
/// "none" with the relative path "networks" when none does. Never throws.
NetworkDirLocation FindNetworkDir(const std::filesystem::path& anchor = {},
                                  const std::filesystem::path& package_dir = {});
/// FindNetworkDir().dir; in a program built against the installed package (find_package(dualgrid)
/// defines DUALGRID_PACKAGE_NETWORK_DIR for it), the package's networks. Never throws: a folder
/// without the network asked for is an std::invalid_argument of CoSimulation::Start
/// (ResolveNetwork) naming the folder and DUALGRID_NETWORK_DIR.
inline std::filesystem::path DefaultNetworkDir() {
#ifdef DUALGRID_PACKAGE_NETWORK_DIR
  return FindNetworkDir({}, DUALGRID_PACKAGE_NETWORK_DIR).dir;
#else
  return FindNetworkDir().dir;
#endif
}

/// True when a scenario's `network` is a file path (it ends in .xml or .xml.gz, or has a '/'),
/// false for the name of a built network ("highway").
bool IsNetworkPath(const std::string& network);

/// Resolves a scenario's network to an existing .net.xml file: a name ("highway") is looked up
/// in `network_dir`; a path ending in .xml is taken as it is (the scenario loader has already
/// made a relative path relative to the scenario file). Throws std::invalid_argument naming the
/// path it looked for and, for a name, the networks that are built.
std::filesystem::path ResolveNetwork(const std::string& network,
                                     const std::filesystem::path& network_dir);

/// "SUMO time [B, E] s (run time [0, D] s)": the run's window on both clocks, for messages.
std::string RunWindow(const ScenarioSpec& spec);

/// Writes the SUMO route file (vTypes, routes, vehicles, flows) for a scenario.
void WriteRouteFile(const ScenarioSpec& spec, const std::filesystem::path& path);

class SumoSimulation {
 public:
  /// Starts SUMO. `work_dir` receives the generated route file, SUMO's message log, the copies of
  /// additional files that declare outputs (sumo_additional/) and those outputs (sumo_outputs/).
  /// SUMO starts at spec.begin (SUMO time) and runs spec.duration. With `ego: {from_routes:
  /// auto}` a first run of SUMO over that window chooses the ego (auto_ego.hpp,
  /// docs/scenarios.md); it throws std::invalid_argument when no vehicle departs in the window.
  /// Throws std::invalid_argument with a one-line message for input SUMO refuses,
  /// std::runtime_error when a file cannot be written.
  SumoSimulation(const ScenarioSpec& spec, const std::filesystem::path& network_file,
                 const std::filesystem::path& work_dir);
  ~SumoSimulation();
  SumoSimulation(const SumoSimulation&) = delete;
  SumoSimulation& operator=(const SumoSimulation&) = delete;

  /// With `ego: {from_routes: auto}`: the first run's choice and its reason (auto_ego.hpp).
  const std::optional<AutoEgoChoice>& auto_ego_choice() const { return auto_choice_; }
  /// Run time [s since spec.begin] of a SUMO time [s], in SUMO's whole milliseconds.
  double RunTime(double sumo_time) const;
  /// "SUMO time T s (run time T - begin s)", for messages.
  std::string Clock(double sumo_time) const;

  /// Advances one step (spec.step_length) and refreshes frame(); frame().time is run time [s
  /// since spec.begin]. Returns false once the scenario
  /// duration is reached or the ego has left the network.
  bool Step();
  /// Ends SUMO, which then writes out the outputs of the additional files; frame(), ego_id()
  /// and the end state stay readable. Step() must not be called afterwards. Idempotent.
  void Close();
  /// Ground truth after the last Step().
  const Frame& frame() const { return frame_; }
  /// The ego's id: the scenario's, or the one `auto` chose (ChooseAutoEgo, docs/scenarios.md).
  const std::string& ego_id() const { return spec_.ego.id; }
  /// Why Step() returned false: the ego left the network (its route ended) before the duration.
  bool ego_left() const { return ego_left_; }
  /// SUMO reached the scenario's duration (the run's frames start at the ego's departure).
  bool reached_end() const { return step_ >= spec_.StepCount(); }
  const ScenarioSpec& spec() const { return spec_; }
  /// Outputs declared by the additional files, as written inside the run folder.
  const std::vector<RedirectedOutput>& redirected_outputs() const { return redirected_outputs_; }
  /// A lane's centre line (world frame) and width, for pictures.
  struct LaneShape {
    std::string id;
    std::vector<Position> points;
    double width = 3.5;
  };
  /// All non-internal lanes of the network.
  std::vector<LaneShape> LaneShapes() const;

 private:
  struct LaneGeometry {
    std::vector<Position> points;
    std::vector<double> s;  // cumulative length at each point
  };
  const LaneGeometry& Lane(const std::string& lane_id);
  VehicleState ReadVehicle(const std::string& id);
  // The scenario's type, or (for vehicles of the user's route files) SUMO's, cached by type id.
  const VehicleTypeSpec& TypeOf(const std::string& vehicle, const std::string& type);
  // libsumo::Simulation::step; SUMO's other exceptions (a definition of the user's files refused
  // when it is loaded) become std::invalid_argument in one line naming the files.
  void SumoStep();
  void ApplyDepartures();
  void ApplyActions();
  // Checks the scenario against the loaded network: every route edge exists and consecutive
  // edges connect, departure lanes exist and positions lie on the first edge. Throws
  // std::invalid_argument naming the key.
  void CheckAgainstNetwork() const;

  ScenarioSpec spec_;
  std::filesystem::path log_path_;  ///< SUMO's message log, named in errors
  Frame frame_;
  int step_ = 0;
  bool ego_left_ = false;
  bool closed_ = false;
  std::vector<RedirectedOutput> redirected_outputs_;
  std::optional<AutoEgoChoice> auto_choice_;
  std::size_t next_action_ = 0;
  std::map<std::string, LaneGeometry> lanes_;
  std::map<std::string, double> previous_yaw_;
  std::map<std::string, VehicleTypeSpec> sumo_types_;
  std::set<std::string> own_types_;  // the scenario's types written to its route file
  std::uint64_t departures_ = 0;
};

}  // namespace dualgrid::sim
