// ground_truth.csv (outputs/csv_writers.hpp) formats its numbers without printf: the bytes must be
// what printf's "%.<n>f" writes (FormatFixed), for ordinary values, halfway decimals, negative
// zero, huge values and NaN.
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <sstream>
#include <string>

#include "dualgrid/core/text.hpp"
#include "dualgrid/outputs/csv_writers.hpp"

namespace fs = std::filesystem;
using dualgrid::FormatFixed;
using dualgrid::Pose2;
using dualgrid::Position;
using dualgrid::Velocity;
using dualgrid::sim::Frame;
using dualgrid::sim::VehicleState;

namespace {

// The rows as the writer wrote them with streams and FormatFixed before.
std::string Reference(const Frame& f) {
  const Pose2 ego = f.EgoPose();
  std::ostringstream os;
  auto row = [&](const VehicleState& v, bool is_ego) {
    const Position p = ego.ToLocal(v.box.center);
    const Velocity vr = ego.RotateToLocal(v.velocity);
    os << f.step << ',' << FormatFixed(f.time, 3) << ',' << v.id << ',' << v.type << ','
       << (is_ego ? 1 : 0) << ',' << FormatFixed(v.box.center.x(), 4) << ','
       << FormatFixed(v.box.center.y(), 4) << ',' << FormatFixed(v.box.yaw, 6) << ','
       << FormatFixed(v.velocity.x(), 4) << ',' << FormatFixed(v.velocity.y(), 4) << ','
       << FormatFixed(v.speed, 4) << ',' << FormatFixed(v.lateral_speed, 4) << ','
       << FormatFixed(v.yaw_rate, 6) << ',' << FormatFixed(v.box.length, 3) << ','
       << FormatFixed(v.box.width, 3) << ',' << v.lane << ',' << FormatFixed(p.x(), 4) << ','
       << FormatFixed(p.y(), 4) << ',' << FormatFixed(vr.x(), 4) << ',' << FormatFixed(vr.y(), 4)
       << ',' << FormatFixed(v.rcs_dbsm, 1) << '\n';
  };
  row(f.ego, true);
  for (const auto& v : f.vehicles) row(v, false);
  return os.str();
}

}  // namespace

TEST_CASE("ground_truth.csv's numbers are printf's, byte for byte", "[outputs]") {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> any(-5000.0, 5000.0), small(-1.0, 1.0);
  // Values that test the rounding: halfway decimals (exact in binary and not), negative zero and
  // values that round to it, the largest and the non-finite.
  const double special[] = {0.00005,
                            0.00015,
                            2.5e-5,
                            -0.0,
                            -1e-9,
                            0.0625,
                            1.0 / 3.0,
                            123456.78951,
                            1e300,
                            -1e200,
                            5e-324,
                            std::numeric_limits<double>::quiet_NaN(),
                            -std::numeric_limits<double>::infinity(),
                            0.125,
                            0.3125,
                            0.5};
  Frame f;
  f.step = 1234;
  f.time = 61.7;
  f.ego.id = "ego";
  f.ego.type = "car";
  f.ego.box = {Position(1.5, -2.25), 0.3, 4.5, 1.8};
  f.ego.velocity = Velocity(20.0, 0.1);
  for (int k = 0; k < 200; ++k) {
    VehicleState v;
    v.id = "v" + std::to_string(k);
    v.type = "truck";
    v.lane = "e1_" + std::to_string(k % 3);
    const auto pick = [&](int i) { return (k + i) % 5 == 0 ? special[(k + i) % 16] : any(rng); };
    v.box = {Position(pick(0), pick(1)), small(rng) * 3.2, pick(2), pick(3)};
    v.velocity = Velocity(pick(4), pick(5));
    v.speed = pick(6);
    v.lateral_speed = pick(7);
    v.yaw_rate = pick(8);
    v.rcs_dbsm = pick(9);
    f.vehicles.push_back(v);
  }
  const fs::path file =
      fs::temp_directory_path() / ("dualgrid_gt_" + std::to_string(::getpid()) + ".csv");
  {
    dualgrid::outputs::GroundTruthWriter w(file);
    w.Write(f);
    w.Close();
  }
  std::ifstream in(file);
  std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  fs::remove(file);
  const std::size_t header = text.find('\n') + 1;
  CHECK(text.substr(header) == Reference(f));
  CHECK(text.find("nan") != std::string::npos);  // the special values were written
  CHECK(text.find("-0.0000") != std::string::npos);
}
