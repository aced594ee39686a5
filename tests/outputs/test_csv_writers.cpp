// ground_truth.csv (outputs/csv_writers.hpp) formats its numbers without printf: the bytes must be
// what printf's "%.<n>f" writes (FormatFixed), for ordinary values, halfway decimals, negative
// zero, huge values and NaN. weights.csv's sums (outputs/weight_traces.hpp, ParticleRuns) must be
// those of the scan of every particle, bit for bit.
#include <unistd.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <sstream>
#include <string>

#include "dualgrid/core/text.hpp"
#include "dualgrid/outputs/csv_writers.hpp"
#include "dualgrid/outputs/weight_traces.hpp"

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

namespace {

using dualgrid::BoxTest;
using dualgrid::OrientedBox;
using dualgrid::filter::ParticleSet;
using dualgrid::outputs::BoxWeights;

// WeightTraces::Add's sums as they were: every particle scanned in index order against the box's
// bounds (with the 1e-6 m margin) and BoxTest.
BoxWeights ScanEveryParticle(const ParticleSet& p, const OrientedBox& box, const Velocity& v) {
  BoxWeights s;
  const BoxTest grown(box);
  Position lo = box.center, hi = box.center;
  for (const Position& c : box.Corners()) lo = lo.cwiseMin(c), hi = hi.cwiseMax(c);
  lo -= Position::Constant(1e-6);
  hi += Position::Constant(1e-6);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double x = p.x[i], y = p.y[i];
    if (x < lo.x() || x > hi.x() || y < lo.y() || y > hi.y()) continue;
    if (!grown.Contains(Position(x, y))) continue;
    s.w_position += p.w_position[i];
    s.w_velocity += p.w_velocity[i];
    s.weight += p.weight[i];
    if ((Velocity(p.vx[i], p.vy[i]) - v).norm() < dualgrid::outputs::WeightTrace::kGoodVelocity) {
      s.w_position_good += p.w_position[i];
      s.w_velocity_good += p.w_velocity[i];
    }
  }
  return s;
}

bool SameBits(const BoxWeights& a, const BoxWeights& b) {
  const double va[] = {a.w_position, a.w_velocity, a.weight, a.w_position_good, a.w_velocity_good};
  const double vb[] = {b.w_position, b.w_velocity, b.weight, b.w_position_good, b.w_velocity_good};
  return std::memcmp(va, vb, sizeof va) == 0;
}

}  // namespace

TEST_CASE("ParticleRuns' box sums are the scan of every particle, bit for bit", "[outputs]") {
  std::mt19937_64 rng(37);
  std::uniform_real_distribution<double> pos(-30.0, 30.0), speed(-6.0, 6.0), weight(0.0, 1e-3);
  std::uniform_int_distribution<int> pick(0, 19);
  const double huge = 1e300, inf = std::numeric_limits<double>::infinity();
  int counted = 0, boxes = 0;
  for (int set = 0; set < 40; ++set) {
    // Sizes around whole runs; positions in clusters, sorted along y in half the sets (as the
    // filter's cell order) and shuffled in the others.
    const std::size_t n = std::size_t{1} + static_cast<std::size_t>(set) * 53 % 700 +
                          (set % 4 == 0 ? dualgrid::outputs::ParticleRuns::kRun * 8 : 0);
    ParticleSet p;
    for (auto* c : {&p.x, &p.y}) c->resize(n);
    for (auto* c : {&p.vx, &p.vy, &p.w_position, &p.w_velocity, &p.weight}) c->resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      const int k = pick(rng);
      // Dyadic positions on the test boxes' edges and corners, extreme and infinite ones.
      p.x[i] = k == 0 ? 2.0 : k == 1 ? -huge : k == 2 ? inf : k == 3 ? 1e15 : pos(rng);
      p.y[i] = k == 0 ? 1.0 : k == 1 ? huge : k == 2 ? -1.5 : k == 4 ? -inf : pos(rng);
      if (k == 5) p.x[i] = -2.0, p.y[i] = -1.0;
      if (k == 6) p.x[i] = 0.5, p.y[i] = 0.25;                  // inside boxes 0 and 1
      p.vx[i] = static_cast<float>(k == 6 ? 2.0 : speed(rng));  // |v - box velocity| = 2: not good
      p.vy[i] = static_cast<float>(k == 6 ? 0.0 : speed(rng));
      p.w_position[i] = static_cast<float>(weight(rng));
      p.w_velocity[i] = static_cast<float>(weight(rng));
      p.weight[i] = static_cast<float>(weight(rng));
    }
    if (set % 2 == 0) {
      std::vector<std::size_t> order(n);
      for (std::size_t i = 0; i < n; ++i) order[i] = i;
      std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        return std::floor(p.y[a]) < std::floor(p.y[b]);
      });
      const ParticleSet copy = p;
      for (std::size_t i = 0; i < n; ++i) p.CopyFrom(copy, order[i], i);
    }
    const dualgrid::outputs::ParticleRuns runs(p);
    for (int b = 0; b < 30; ++b) {
      // Box 0: axis-aligned 4 x 2 at the origin, its edges through the dyadic particles; box 1
      // turned a quarter; box 2 far out among the extreme coordinates; the rest random.
      const OrientedBox box =
          b == 0   ? OrientedBox{Position(0, 0), 0.0, 4.0, 2.0}
          : b == 1 ? OrientedBox{Position(0, 0), 0.5 * dualgrid::kPi, 2.0, 4.0}
          : b == 2 ? OrientedBox{Position(1e15, 0), 0.3, 1e3, 1e3}
                   : OrientedBox{Position(pos(rng), pos(rng)), pos(rng) * 0.1,
                                 0.5 + std::abs(pos(rng)) * 0.4, 0.5 + std::abs(pos(rng)) * 0.2};
      const Velocity v(b < 2 ? 0.0 : speed(rng), b < 2 ? 0.0 : speed(rng));
      const BoxWeights want = ScanEveryParticle(p, box, v), got = runs.Sum(box, v);
      CHECK(SameBits(got, want));
      counted += want.w_position > 0.0;
      ++boxes;
    }
  }
  CHECK(counted > boxes / 3);  // most boxes hold particles: the sums were exercised
}
