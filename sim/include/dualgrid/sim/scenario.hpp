// Traffic scenario parameters: what SUMO runs. Filled by the scenario loader, validated here.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "dualgrid/core/types.hpp"
#include "dualgrid/sim/auto_ego.hpp"

namespace dualgrid::sim {

/// Radar cross-sections a scenario may give [dBsm]: from a small animal to a ship's side. The
/// radar equation takes 10^(rcs / 10): far beyond these (1e300) it overflows to inf and the
/// filter's weights to NaN.
inline constexpr double kMinRcsDbsm = -60.0;
inline constexpr double kMaxRcsDbsm = 80.0;

/// A vehicle class: SUMO vType attributes plus the radar cross-section the radar model uses.
struct VehicleTypeSpec {
  double length = 4.5;               ///< [m]
  double width = 1.8;                ///< [m]
  double max_speed = 40.0;           ///< [m/s] vehicle limit
  double accel = 2.6;                ///< [m/s^2]
  double decel = 4.5;                ///< [m/s^2]
  double rcs_dbsm = 10.0;            ///< radar cross-section [dBsm]
  std::string vclass = "passenger";  ///< SUMO vClass
  bool overtake_right = false;  ///< SUMO lcOvertakeRight: may pass slower vehicles on their right
};

/// How the ego's speed is chosen.
struct SpeedPolicy {
  enum class Mode { kCruise, kFixed, kSumo };
  /// kCruise: SUMO drives with `speed` as desired speed (car following applies);
  /// kFixed: the speed is imposed every step (traffic is ignored);
  /// kSumo: as the SUMO route file says (an ego taken from route files without speed_policy).
  Mode mode = Mode::kCruise;
  double speed = 27.78;  ///< [m/s]
};

/// One explicitly placed vehicle (the ego uses the same fields).
struct VehicleSpec {
  std::string id;
  std::string type = "car";
  std::string route;      ///< name of an entry of ScenarioSpec::routes
  double depart = 0.0;    ///< [s] run time (from ScenarioSpec::begin)
  int lane = 0;           ///< departure lane index (0 = rightmost)
  double position = 0.0;  ///< [m] departure position of the front bumper along the first edge
  double speed = 27.78;   ///< [m/s] departure speed
  std::optional<double> desired_speed;  ///< [m/s] cruise speed; default: the type's max_speed
                                        ///< (the ego's comes from its speed policy)
  bool lane_change = true;              ///< false: SUMO never changes its lane on its own
};

/// A SUMO flow: vehicles of one type on one route at a fixed period.
struct FlowSpec {
  std::string id;
  std::string type = "car";
  std::string route;
  double begin = 0.0;         ///< [s] run time (from ScenarioSpec::begin)
  double end = 60.0;          ///< [s] run time
  double period = 5.0;        ///< [s] between departures
  std::string lane = "best";  ///< SUMO departLane: an index, "random", "free", "best"
  double position = 0.0;      ///< [m] departure position along the first edge
  double speed_min = 19.44;   ///< [m/s] desired speeds are drawn in [speed_min, speed_max]
  double speed_max = 36.11;   ///< [m/s]
};

/// A scripted event at a time: a speed change or a lane change of one vehicle.
struct ActionSpec {
  double time = 0.0;  ///< [s] run time (from ScenarioSpec::begin)
  std::string vehicle;
  std::optional<double> set_speed;  ///< [m/s] new desired speed
  std::optional<int> change_lane;   ///< target lane index
  double duration = 3.0;  ///< [s] how long SUMO keeps the lane-change request / speed ramp
};

/// A guard rail (or any thin static line) in world coordinates.
struct GuardRail {
  std::string id;
  std::vector<Position> points;
  double rcs_dbsm_per_metre = -5.0;  ///< [dBsm per metre of rail]
};

/// A parked vehicle or other static box.
struct ParkedBox {
  std::string id;
  OrientedBox box;
  double rcs_dbsm = 10.0;
};

/// When a vehicle of the user's files departs (sumo_files.hpp, DepartureOf): at `depart` [s, SUMO
/// time]; the k-th member of a flow at max(depart, the run's begin) + k * period (SUMO starts a
/// flow that began before the run at the run's begin, numbering from 0), if before `flow_end`.
struct FileDeparture {
  double depart = 0.0;
  std::optional<double> period;  ///< set for a flow member: its flow's period [s]
  long member = 0;
  std::optional<double> flow_end;  ///< [s, SUMO time]
  /// The departure [s, SUMO time] in a run beginning at `begin`; std::nullopt when SUMO creates
  /// no such vehicle (a flow member past the flow's end).
  std::optional<double> At(double begin) const;
};

/// Random traffic from SUMO's randomTrips.py (random_trips.hpp): `traffic.random_trips`, or by
/// default for a scenario with `ego: {from_routes: auto}` and no traffic of its own.
struct RandomTripsSpec {
  double period = 2.0;  ///< [s] between departures
};

/// `ego: {from_routes: auto}`: the ego is chosen from the route files' vehicles by a dry run of
/// SUMO (sumo_simulation.hpp, ChooseAutoEgo).
inline constexpr const char* kAutoEgo = "auto";

struct ScenarioSpec {
  std::string file;  ///< the scenario file it came from, named in error messages ("" if none)
  std::string name;
  std::string description;
  /// A built network's name (<network dir>/<name>.net.xml) or a path to a .net.xml file.
  std::string network;
  /// The run's first instant on SUMO's clock [s, SUMO time]: SUMO starts there and the run
  /// covers SUMO time [begin, begin + duration]. Its source: `begin_source`.
  double begin = 0.0;
  /// Where `begin` came from: "default" (0), "sumo_config" (the configuration's <begin>, as SUMO
  /// read it), "scenario" (the key `begin`) or "command line" (--begin).
  std::string begin_source = "default";
  /// The configuration's <end> [s, SUMO time] when it gives one: begin must lie before it.
  std::optional<double> config_end;
  double duration = 60.0;     ///< [s] run time: counted from `begin`
  double step_length = 0.05;  ///< [s] SUMO step = radar cycle
  std::uint64_t seed = 1;
  double lane_change_duration = 3.0;  ///< [s] SUMO --lanechange.duration: continuous lane changes

  std::map<std::string, VehicleTypeSpec> vehicle_types;
  std::map<std::string, std::vector<std::string>> routes;  ///< name -> edge ids
  VehicleSpec ego;
  SpeedPolicy ego_speed;
  std::vector<VehicleSpec> vehicles;
  std::vector<FlowSpec> flows;
  std::vector<ActionSpec> actions;
  std::vector<GuardRail> guard_rails;
  std::vector<ParkedBox> parked;
  /// SUMO route files (absolute paths) simulated besides the scenario's own vehicles
  /// (`traffic.route_files`, or the route-files of `sumo_config`). Their vehicles are scored like
  /// the others: box from their vType's length and width, RCS from `type_rcs` or VClassRcs.
  std::vector<std::string> route_files;
  /// SUMO additional files (absolute paths): vTypes, traffic-light programs, stops, rerouters,
  /// polygons, ... loaded by SUMO as they are, before the route files (`traffic.additional_files`,
  /// or the additional-files of `sumo_config`); the outputs they declare are written inside the
  /// run folder (sumo_additional.hpp).
  std::vector<std::string> additional_files;
  /// True: the ego is the vehicle `ego.id` of route_files or additional_files
  /// (`ego: {from_routes: ID}`), not one
  /// the scenario places. ID kAutoEgo ("auto"): SumoSimulation chooses it (ChooseAutoEgo).
  bool ego_from_routes = false;
  /// `ego.from_routes` naming a vehicle of the files: when it departs (checked against the run's
  /// window by IsValid, so a --begin or --duration given later is checked too).
  std::optional<FileDeparture> ego_departure;
  /// Random traffic generated when SUMO starts (into its work folder), added to route_files.
  std::optional<RandomTripsSpec> random_trips;
  /// The grid around a vehicle, for the `auto` rule (auto_ego.hpp; the loader sets it from the
  /// filter's extent and placement).
  ViewBox auto_ego_view;
  /// The map the user named when `network` is made from it (an OpenDRIVE .xodr converted into
  /// the cache, opendrive.hpp); "" otherwise.
  std::string network_source;
  /// Radar cross-section [dBsm] per vType id of route_files (`traffic.rcs_dbsm`).
  std::map<std::string, double> type_rcs;
  /// Parts of the input that are not honoured, one line each naming the file and the element
  /// (filled by the loader; the tools print them as warnings).
  std::vector<std::string> warnings;

  /// Checks ranges and cross references; `error` names the offending field.
  bool IsValid(std::string* error) const;
  /// Number of simulation steps.
  int StepCount() const;
};

/// Default radar cross-section [dBsm] of a SUMO vClass for vehicles of route files whose type
/// the scenario does not give one (docs/scenarios.md, "Bring your own SUMO scenario"): passenger
/// car 10, van (delivery) 14, truck / trailer / bus / coach 25, motorcycle 5, moped 3, bicycle 0
/// (typical 77 GHz values of the literature, rounded); any other class 10.
double VClassRcs(const std::string& vclass);

/// The longest run [s]: a day of simulated traffic (docs/scenarios.md, "Time of day").
inline constexpr double kMaxDuration = 86400.0;
/// The latest begin [s, SUMO time]: a year.
inline constexpr double kMaxBegin = 365.0 * 86400.0;

/// Speed band of the paper's scenarios (70-130 km/h), used to validate traffic speeds.
inline constexpr double kMinTrafficSpeed = 0.0;
inline constexpr double kMaxTrafficSpeed = 70.0;

}  // namespace dualgrid::sim
