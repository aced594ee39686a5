// dualgrid::recorded on its own (no co-simulation, no SUMO): a run folder written by hand from the
// shared column schema (run_folder_columns.hpp) is read back by ReadRunFolder.
#include <catch2/catch.hpp>

#include <unistd.h>
#include <filesystem>
#include <fstream>
#include <string>

#include "dualgrid/recorded/run_folder.hpp"
#include "dualgrid/recorded/run_folder_columns.hpp"

namespace fs = std::filesystem;
using namespace dualgrid::recorded;

namespace {

// A row with `value` in column `column` of `names` and "0" elsewhere (text columns get names).
template <std::size_t N>
std::string Row(const std::array<std::string_view, N>& names,
                const std::vector<std::pair<std::string_view, std::string>>& values) {
  std::string row;
  for (std::string_view n : names) {
    std::string v = "0";
    for (const auto& [k, x] : values)
      if (k == n) v = x;
    row += (row.empty() ? "" : ",") + v;
  }
  return row;
}

}  // namespace

TEST_CASE("a run folder written from the column schema reads back without SUMO") {
  const fs::path dir =
      fs::temp_directory_path() / ("dualgrid_recorded_alone_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  {
    std::ofstream scans(dir / "scans.csv");
    scans << JoinColumns(kScanColumns) << "\n";
    for (int step : {0, 1})
      scans << Row(kScanColumns, {{"step", std::to_string(step)},
                                  {"time", step ? "0.1" : "0.05"},
                                  {"sensor_name", "front"},
                                  {"ego_x", "10.5"},
                                  {"ego_vx", "20"},
                                  {"ego_length", "4.5"},
                                  {"ego_width", "1.8"},
                                  {"mount_x", "3.7"},
                                  {"fov", "1.5"},
                                  {"min_range", "0.5"},
                                  {"max_range", "150"}})
            << "\n";
    std::ofstream det(dir / "detections.csv");
    det << JoinColumns(kDetectionColumns) << "," << kVClassColumn << "\n";
    det << Row(kDetectionColumns, {{"step", "1"},
                                   {"range", "12.25"},
                                   {"x", "22.5"},
                                   {"y", "-1.25"},
                                   {"radial_speed", "-3.5"},
                                   {"source", "car7"}})
        << ",passenger\n";
  }
  const RecordedSequence seq = ReadRunFolder(dir);
  REQUIRE(seq.scans.size() == 2);
  REQUIRE(seq.sensors.size() == 1);
  CHECK(seq.sensors[0].name == "front");
  CHECK(seq.sensors[0].mount.position.x() == 3.7);
  CHECK(seq.ego_length == 4.5);
  CHECK(seq.scans[0].ego_pose.position.x() == 10.5);
  CHECK(seq.scans[0].ego_velocity.x() == 20.0);
  REQUIRE(seq.points.size() == 1);
  CHECK(seq.scans[1].begin == 0);
  CHECK(seq.scans[1].end == 1);
  CHECK(seq.points[0].range == 12.25);
  CHECK(seq.points[0].position.y() == -1.25);
  CHECK(seq.points[0].radial_speed == -3.5);
  CHECK(IsMovingLabel(seq.points[0].label));
  REQUIRE(seq.track_names.size() == 1);
  CHECK(seq.track_names[0] == "car7");
  fs::remove_all(dir);
}

TEST_CASE("a run folder without a schema column is refused naming it") {
  const fs::path dir =
      fs::temp_directory_path() / ("dualgrid_recorded_missing_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::string header = JoinColumns(kScanColumns);
  header.erase(header.find(",lane_yaw"), std::string(",lane_yaw").size());
  std::ofstream(dir / "scans.csv") << header << "\n";
  std::ofstream(dir / "detections.csv") << JoinColumns(kDetectionColumns) << ",vclass\n";
  CHECK_THROWS_WITH(ReadRunFolder(dir), Catch::Contains("'lane_yaw'"));
  fs::remove_all(dir);
}
