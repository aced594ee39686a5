// SUMO's own files as input (issue 16, docs/scenarios.md "Bring your own SUMO scenario"): a
// .sumocfg with route files, the ego taken from them by id, SUMO vehicle types mapped to boxes and
// radar cross-sections, and one-line messages for what cannot be honoured.
#include <sys/stat.h>

#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_harness.hpp"

using namespace dualgrid::testing;

namespace {

// A SUMO user's folder: a straight two-lane road, a route file written as duarouter would (own
// vTypes, vehicles with inline routes, a flow, a person), an additional file (a vType that only
// it defines, a bus stop, a detector and an edgeData output, a polygon and a POI, an id inside a
// comment), and a .sumocfg naming them.
fs::path WriteSumoFolder(const fs::path& dir) {
  std::ofstream(dir / "road.nod.xml")
      << "<nodes>\n  <node id=\"w\" x=\"0\" y=\"0\"/>\n  <node id=\"e\" x=\"1500\" y=\"0\"/>\n"
      << "</nodes>\n";
  std::ofstream(dir / "road.edg.xml")
      << "<edges>\n  <edge id=\"we\" from=\"w\" to=\"e\" numLanes=\"2\" speed=\"33.3\"/>\n"
      << "  <edge id=\"ew\" from=\"e\" to=\"w\" numLanes=\"2\" speed=\"33.3\"/>\n</edges>\n";
  const auto nc = Shell(std::string(DUALGRID_NETCONVERT) + " --node-files " +
                        (dir / "road.nod.xml").string() + " --edge-files " +
                        (dir / "road.edg.xml").string() + " -o " + (dir / "road.net.xml").string());
  INFO(nc.output);
  REQUIRE(nc.code == 0);
  std::ofstream(dir / "traffic.rou.xml")
      << "<routes>\n"
      << "  <vType id=\"pkw\" vClass=\"passenger\" length=\"4.6\" width=\"1.9\"/>\n"
      << "  <vType id=\"lkw\" vClass=\"truck\" length=\"16.5\" width=\"2.55\" maxSpeed=\"25\"/>\n"
      // The ego's type: longer and wider than the scenario's default car (4.5 m x 1.8 m).
      << "  <vType id=\"suv\" vClass=\"passenger\" length=\"5.2\" width=\"2.0\"/>\n"
      << "  <vehicle id=\"veh_ego\" type=\"suv\" depart=\"0\" departPos=\"200\" departLane=\"0\""
         " departSpeed=\"20\">\n    <route edges=\"we\"/>\n  </vehicle>\n"
      << "  <vehicle id=\"lead\" type=\"pkw\" depart=\"0\" departPos=\"240\" departLane=\"0\""
         " departSpeed=\"18\">\n    <route edges=\"we\"/>\n  </vehicle>\n"
      << "  <vehicle id=\"truck_1\" type=\"lkw\" depart=\"0\" departPos=\"260\" departLane=\"1\""
         " departSpeed=\"22\">\n    <route edges=\"we\"/>\n  </vehicle>\n"
      << "  <flow id=\"oncoming\" type=\"pkw\" begin=\"0\" end=\"20\" period=\"4\" from=\"ew\""
         " to=\"ew\" departSpeed=\"max\"/>\n"
      << "  <vehicle id=\"van_1\" type=\"van\" depart=\"0\" departPos=\"150\" departLane=\"1\""
         " departSpeed=\"20\">\n    <route edges=\"we\"/>\n  </vehicle>\n"
      << "  <person id=\"walker\" depart=\"0\">\n    <walk edges=\"we\"/>\n  </person>\n"
      << "  <!-- <vehicle id=\"ghost\" depart=\"0\"/> -->\n"
      << "</routes>\n";
  std::ofstream(dir / "extra.add.xml")
      << "<additional>\n"
      << "  <vType id=\"van\" vClass=\"delivery\" length=\"6.0\" width=\"2.1\"/>\n"
      << "  <busStop id=\"stop_1\" lane=\"we_0\" startPos=\"900\" endPos=\"920\"/>\n"
      << "  <e1Detector id=\"loop_1\" lane=\"we_0\" pos=\"400\" freq=\"5\" "
         "file=\"det/loops.xml\"/>\n"
      << "  <edgeData id=\"dump\" freq=\"5\" file=\"edges.xml\"/>\n"
      << "  <poly id=\"building\" type=\"building\" color=\"red\" shape=\"100,20 120,20 "
         "120,40\"/>\n"
      << "  <poi id=\"tree\" x=\"300\" y=\"15\"/>\n"
      << "</additional>\n";
  std::ofstream(dir / "case.sumocfg")
      << "<configuration>\n  <input>\n    <net-file value=\"road.net.xml\"/>\n"
      << "    <route-files value=\"traffic.rou.xml\"/>\n"
      << "    <additional-files value=\"extra.add.xml\"/>\n  </input>\n"
      << "  <time>\n    <step-length value=\"0.5\"/>\n  </time>\n</configuration>\n";
  return dir / "case.sumocfg";
}

}  // namespace

TEST_CASE("a run from a .sumocfg with its route files and the ego chosen by id", "[cli][sumo]") {
  const fs::path dir = TempDir("sumo_files", "run");
  WriteSumoFolder(dir);
  std::ofstream(dir / "scenario.yaml") << "name: own_sumo\nsumo_config: case.sumocfg\n"
                                       << "duration: 12.0\nego: {from_routes: veh_ego}\n"
                                       << "traffic: {rcs_dbsm: {lkw: 23.0}}\n"
                                       << "evaluation: {focus_object: lead}\n";
  const auto r = Run("run " + (dir / "scenario.yaml").string() + " --out " +
                     (dir / "out").string() + " --no-figures -q --detections csv");
  INFO(r.output);
  REQUIRE(r.code == 0);
  // What cannot be honoured is named, one line each, with the file and the element.
  CHECK(r.output.find("dualgrid: warning: " + (dir / "traffic.rou.xml").string() +
                      ": 1 <person> element(s)") != std::string::npos);
  CHECK(r.output.find("dualgrid: warning: " + (dir / "extra.add.xml").string() +
                      ": 1 <poly> element(s): SUMO loads them, but the radar model does not see "
                      "them") != std::string::npos);
  CHECK(r.output.find("is not loaded") == std::string::npos);
  CHECK(r.output.find("its step-length 0.5 s is replaced by step_length 0.05 s") !=
        std::string::npos);
  // The route file's vehicles are the ground truth, with their vType's box and RCS by vClass
  // (passenger 10 dBsm) or the scenario's per-type value (lkw 23 dBsm).
  std::set<std::string> ids;
  bool ego_seen = false;
  for (const auto& row : ReadCsv(dir / "out" / "ground_truth.csv")) {
    ids.insert(row.at("id"));
    if (row.at("id") == "veh_ego") {
      ego_seen = true;
      CHECK(row.at("is_ego") == "1");
    }
    if (row.at("id") == "truck_1") {
      CHECK(row.at("length") == "16.500");
      CHECK(row.at("width") == "2.550");
      CHECK(row.at("rcs_dbsm") == "23.0");
    }
    if (row.at("id") == "lead") {
      CHECK(row.at("length") == "4.600");
      CHECK(row.at("rcs_dbsm") == "10.0");
    }
    // A vType of the additional file (SUMO loads it before the route files).
    if (row.at("id") == "van_1") {
      CHECK(row.at("length") == "6.000");
      CHECK(row.at("rcs_dbsm") == "14.0");
    }
  }
  CHECK(ego_seen);
  CHECK(ids.count("lead"));
  CHECK(ids.count("van_1"));
  // The additional file's outputs are written inside the run folder, never beside its files.
  CHECK_FALSE(fs::exists(dir / "det"));
  CHECK_FALSE(fs::exists(dir / "edges.xml"));
  CHECK(Slurp(dir / "out" / "sumo_outputs" / "loops.xml").find("<interval") != std::string::npos);
  CHECK(Slurp(dir / "out" / "sumo_outputs" / "edges.xml").find("<interval") != std::string::npos);
  const auto run_summary = nlohmann::json::parse(Slurp(dir / "out" / "summary.json"));
  REQUIRE(run_summary.at("sumo_outputs").size() == 2);
  CHECK(run_summary.at("sumo_outputs")[0].at("original") == "det/loops.xml");
  CHECK(run_summary.at("sumo_outputs")[0].at("element") == "e1Detector");
  CHECK(ids.count("truck_1"));
  CHECK(ids.count("oncoming.0"));
  CHECK_FALSE(ids.count("walker"));
  // And they are scored: the lead vehicle in the ego's lane is tracked.
  bool lead_scored = false;
  for (const auto& row : ReadCsv(dir / "out" / "objects.csv"))
    lead_scored = lead_scored || (row.at("name") == "lead" && row.at("scored") == "1");
  CHECK(lead_scored);
  // The radars sit on the ego's box as SUMO simulates it (5.2 m x 2.0 m): the front radar at
  // +2.6 m, outside the body, sees the lead. (On the scenario type's 4.5 m box it sat 0.35 m
  // inside the body, which hid everything ahead.)
  const auto summary = nlohmann::json::parse(Slurp(dir / "out" / "summary.json"));
  bool front_checked = false;
  for (const auto& s : summary.at("sensors_mounted")) {
    if (s.at("name") != "front") continue;
    CHECK(s.at("x").get<double>() == Approx(2.6));
    front_checked = true;
  }
  CHECK(front_checked);
  int front_lead = 0;
  for (const auto& row : ReadCsv(dir / "out" / "detections.csv"))
    front_lead += row.at("sensor_name") == "front" && row.at("source") == "lead";
  CHECK(front_lead > 100);
}

TEST_CASE("SUMO file inputs that cannot be used are refused naming the key", "[cli][sumo]") {
  const fs::path dir = TempDir("sumo_files", "errors");
  WriteSumoFolder(dir);
  struct Case {
    std::string yaml, expected;
  };
  const std::string flow_hint = "SUMO names its vehicles 'oncoming.0', 'oncoming.1'";
  const std::vector<Case> cases = {
      // The ego must be a vehicle SUMO simulates, resolved from the parsed files at load time.
      {"sumo_config: case.sumocfg\nego: {from_routes: nobody}\n",
       "key 'ego.from_routes': 'nobody' is no vehicle, trip or flow member of the route files "
       "(expected a vehicle, a trip, FLOW.k for a flow's k-th vehicle, or auto; e.g. 'veh_ego', "
       "'lead', 'truck_1', 'van_1', 'oncoming.0')"},
      {"sumo_config: case.sumocfg\nego: {from_routes: oncoming}\n", flow_hint},
      {"sumo_config: case.sumocfg\nego: {from_routes: oncoming.5}\n",
       "'oncoming.5' is no member of flow 'oncoming', which creates 5 vehicle(s): 'oncoming.0' to "
       "'oncoming.4'"},
      {"sumo_config: case.sumocfg\nego: {from_routes: pkw}\n", "'pkw' is a <vType>, not a vehicle"},
      {"sumo_config: case.sumocfg\nego: {from_routes: van}\n", "'van' is a <vType>, not a vehicle"},
      {"sumo_config: case.sumocfg\nego: {from_routes: walker}\n",
       "'walker' is a <person>, not a vehicle"},
      {"sumo_config: case.sumocfg\nego: {from_routes: ghost}\n",
       "'ghost' is no vehicle, trip or flow member"},  // only inside a comment
      {"sumo_config: case.sumocfg\nego: {from_routes: veh_ego}\ntraffic: {rcs_dbsm: {bus: 20}}\n",
       "key 'traffic.rcs_dbsm.bus': no route or additional file defines a vType 'bus' (expected "
       "one of: 'lkw', 'pkw', 'suv', 'van', or DEFAULT_VEHTYPE)"},
      {"network: road.net.xml\nego: {type: car, route: r, lane: 0, position: 10, speed: 10}\n"
       "routes: {r: [we]}\ntraffic: {rcs_dbsm: {lkw: 20}}\n",
       "key 'traffic.rcs_dbsm' gives vType RCS values, but there are no SUMO route or additional "
       "files"},
      {"sumo_config: missing.sumocfg\nego: {from_routes: veh_ego}\n",
       "missing.sumocfg: SUMO configuration not found"},
      {"network: road.net.xml\nsumo_config: case.sumocfg\nego: {from_routes: veh_ego}\n",
       "key 'network' must not be given with sumo_config"},
      {"sumo_config: case.sumocfg\nego: {from_routes: veh_ego, lane: 1}\n",
       "key 'ego.lane' must not be given with from_routes"},
      {"network: road.net.xml\ntraffic: {route_files: [nope.rou.xml]}\n"
       "ego: {from_routes: veh_ego}\n",
       "key 'traffic.route_files': " + (dir / "nope.rou.xml").string() +
           ": SUMO route file not found"},
      // Inputs that would block, never end or are no file at all: refused before any reading.
      {"network: road.net.xml\ntraffic: {route_files: [/dev/zero]}\nego: {from_routes: veh_ego}\n",
       "/dev/zero: SUMO route file is a device, expected a regular file"},
      {"network: road.net.xml\ntraffic: {route_files: [fifo.rou.xml]}\n"
       "ego: {from_routes: veh_ego}\n",
       "fifo.rou.xml: SUMO route file is a FIFO (named pipe), expected a regular file"},
      {"network: road.net.xml\ntraffic: {route_files: [.]}\nego: {from_routes: veh_ego}\n",
       "SUMO route file is a directory, expected a regular file"},
      {"sumo_config: fifo.rou.xml\nego: {from_routes: veh_ego}\n",
       "fifo.rou.xml: SUMO configuration is a FIFO (named pipe)"},
      {"network: road.net.xml\ntraffic: {route_files: [traffic.rou.xml], additional_files: "
       "[broken.add.xml]}\nego: {from_routes: veh_ego}\n",
       (dir / "broken.add.xml").string() + ":3: SUMO additional file is not well-formed XML"},
  };
  REQUIRE(mkfifo((dir / "fifo.rou.xml").c_str(), 0600) == 0);
  std::ofstream(dir / "broken.add.xml") << "<additional>\n  <vType id=\"x\"/>\n  <oops\n";

  for (const Case& c : cases) {
    std::ofstream(dir / "bad.yaml") << "name: bad\n" << c.yaml;
    const auto r = Run("sim " + (dir / "bad.yaml").string() + " --out " + (dir / "out").string() +
                       " -q --duration 1");
    INFO(c.yaml);
    INFO(r.output);
    CHECK(r.code == 2);
    CHECK(r.output.find(c.expected) != std::string::npos);
    CHECK(CountLines(r.output) <= 2);
  }
}

TEST_CASE("the OpenStreetMap example of docs/scenarios.md runs as written", "[cli][sumo]") {
  // sumo-tools (a required package) ships the network and route files it names.
  const fs::path example = fs::path(DUALGRID_SOURCE_DIR) / "docs/examples/osm_motorway/a10.yaml";
  const fs::path out = TempDir("sumo_files", "osm");
  const auto r = Run("run " + example.string() + " --out " + (out / "run").string() +
                     " --duration 5 --no-figures -q");
  INFO(r.output);
  REQUIRE(r.code == 0);
  const auto summary = nlohmann::json::parse(Slurp(out / "run" / "summary.json"));
  // The grid starts along the ego's start heading (155 deg), not along world x, and follows the
  // motorway's bends (grid.csv: where it lay at each step).
  CHECK(summary.at("grid_frame").at("frame") == "follow");
  const auto grid = ReadCsv(out / "run" / "grid.csv");
  REQUIRE(grid.size() == 100);
  CHECK(std::stod(grid.front().at("yaw_deg")) == Approx(155.0).margin(1.0));
  CHECK(summary.at("grid_frame").at("yaw_deg").get<double>() ==
        Approx(std::stod(grid.back().at("yaw_deg"))).epsilon(1e-9));
  // Vehicles of the route files are in the grid and scored.
  int scored = 0;
  for (const auto& row : ReadCsv(out / "run" / "objects.csv")) scored += row.at("scored") == "1";
  CHECK(scored > 0);
}

TEST_CASE("the ego is any vehicle SUMO simulates: a flow member, a trip, or auto", "[cli][sumo]") {
  const fs::path dir = TempDir("sumo_files", "egos");
  WriteSumoFolder(dir);
  // A trip (from/to edges, routed by SUMO) and the files compressed, as SUMO reads them too.
  std::ofstream(dir / "trips.rou.xml")
      << "<routes>\n  <trip id=\"trip_1\" depart=\"1\" from=\"we\" to=\"we\" departLane=\"1\"/>\n"
      << "</routes>\n";
  REQUIRE(
      Shell("gzip -k " + (dir / "trips.rou.xml").string() + " " + (dir / "road.net.xml").string())
          .code == 0);
  struct Case {
    std::string ego, expect;
  };
  for (const Case& c :
       {Case{"oncoming.1", "oncoming.1"}, Case{"trip_1", "trip_1"}, Case{"auto", "veh_ego"}}) {
    std::ofstream(dir / "ego.yaml")
        << "name: ego_" << c.ego << "\nnetwork: road.net.xml.gz\nduration: 8.0\n"
        << "traffic: {route_files: [traffic.rou.xml, trips.rou.xml.gz], additional_files: "
           "[extra.add.xml]}\nego: {from_routes: "
        << c.ego << "}\n";
    const fs::path out = dir / ("out_" + c.ego);
    const auto r = Run("sim " + (dir / "ego.yaml").string() + " --out " + out.string());
    INFO(r.output);
    REQUIRE(r.code == 0);
    const auto summary = nlohmann::json::parse(Slurp(out / "summary.json"));
    CHECK(summary.at("ego") == c.expect);
    CHECK(summary.at("complete") == true);
    bool ego_rows = false;
    for (const auto& row : ReadCsv(out / "ground_truth.csv"))
      if (row.at("is_ego") == "1") ego_rows = ego_rows || row.at("id") == c.expect;
    CHECK(ego_rows);
    // `auto` says whom it chose, and by which rule.
    if (c.ego == "auto")
      CHECK(r.output.find("dualgrid: ego: auto chose 'veh_ego'") != std::string::npos);
  }
}
