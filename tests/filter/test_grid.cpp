#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <omp.h>

#include "dualgrid/core/random.hpp"
#include "dualgrid/filter/dynamic_grid.hpp"
#include "synthetic.hpp"

using namespace dualgrid;
using namespace dualgrid::filter;
using namespace dualgrid::filter::testing;

namespace {

// Random detections around the ego: positions inside the grid, radial velocities up to 40 m/s
// (static, radial and tangential mixes), from one of two sensors.
std::vector<Measurement> RandomDetections(const Pose2& ego, std::uint64_t seed, std::uint64_t step,
                                          const std::vector<SensorCoverage>& cov) {
  CounterRng rng(seed, RngPurpose::kTest, step, 0);
  const int n = static_cast<int>(rng.Uniform() * 60);
  std::vector<Measurement> z;
  for (int i = 0; i < n; ++i) {
    const SensorCoverage& c = cov[i % cov.size()];
    const double range = rng.Uniform(1.0, 90.0);
    const double bearing = c.boresight + rng.Uniform(-c.half_fov, c.half_fov);
    const Position p = c.origin + range * UnitVector(bearing);
    const Velocity v(rng.Uniform(-40.0, 40.0), rng.Uniform(-5.0, 5.0));
    z.push_back(Detect(p, rng.Uniform() < 0.3 ? Velocity::Zero() : v, c.origin));
  }
  (void)ego;
  return z;
}

std::vector<SensorCoverage> Sensors(const Pose2& ego) {
  return {ForwardRadar(ego), LeftRadar(ego)};
}

}  // namespace

TEST_CASE("grid shift moves every layer by whole cells, particles stay in world coordinates",
          "[filter][grid]") {
  // Two grids with the same seed see the same first cycle; in the second cycle B's ego is k cells
  // further. Storage is addressed by world cell, so B must equal A re-indexed by k, bit for bit.
  const int kx = GENERATE(1, 3, -7, 40);
  const int ky = GENERATE(0, 2, -1);
  FilterParams fp;
  fp.num_particles = 3000;
  fp.num_birth = 300;
  DynamicGrid a(fp, 5), b(fp, 5);
  Pose2 ego;
  ego.position = {100.25, -20.1};
  const SensorCoverage cov = ForwardRadar(ego);
  std::vector<Measurement> z;
  for (double x : {20.0, 20.5, 21.0})
    z.push_back(Detect(ego.position + Vector2(x, 1.0), {10, 0}, cov.origin));
  for (double x : {30.0, 30.5})
    z.push_back(Detect(ego.position + Vector2(x, -1.0), {0, 0}, cov.origin));
  a.Update({ego, {0, 0}}, z, std::span<const SensorCoverage>(&cov, 1), 0.05);
  b.Update({ego, {0, 0}}, z, std::span<const SensorCoverage>(&cov, 1), 0.05);
  Pose2 moved = ego;
  moved.position += Vector2(kx * fp.resolution, ky * fp.resolution);
  a.Update({ego, {0, 0}}, {}, {}, 0.05);
  b.Update({moved, {0, 0}}, {}, {}, 0.05);

  REQUIRE(a.particles().size() == b.particles().size());
  // Positions are float grid-local metres (docs/algorithm.md, "Float state"): B subtracts its
  // shift k r (one rounding) before adding the same motion as A (one rounding each), so with M
  // the magnitude of the grid-local values [m] (<= the particle's offset from A's corner plus
  // (|k| + 1) r) the world positions differ by at most 3 2^-24 M < 2^-22 M.
  int particle_mismatch = 0;
  const double r = fp.resolution;
  const double ax0 = static_cast<double>(a.origin_index()[0]) * r;
  const double ay0 = static_cast<double>(a.origin_index()[1]) * r;
  for (std::size_t i = 0; i < a.particles().size(); ++i) {
    const double pa_x = a.particles().x[i], pa_y = a.particles().y[i];
    const double mx = std::abs(pa_x - ax0) / r + std::abs(kx) + 1.0;
    const double my = std::abs(pa_y - ay0) / r + std::abs(ky) + 1.0;
    particle_mismatch += std::abs(pa_x - b.particles().x[i]) > 0x1p-22 * mx * r ||
                         std::abs(pa_y - b.particles().y[i]) > 0x1p-22 * my * r ||
                         a.particles().weight[i] != b.particles().weight[i];
  }
  CHECK(particle_mismatch == 0);
  int compared = 0, nonempty = 0, layer_mismatch = 0, entered_not_unknown = 0, center_mismatch = 0;
  for (int y = 0; y < b.cells_y(); ++y) {
    for (int x = 0; x < b.cells_x(); ++x) {
      const CellState sb = b.Cell({x, y});
      center_mismatch += !b.CellCenter({x, y}).isApprox(a.CellCenter({x + kx, y + ky}));
      const int ax = x + kx, ay = y + ky;
      if (ax < 0 || ay < 0 || ax >= a.cells_x() || ay >= a.cells_y()) {
        entered_not_unknown += sb.unknown != 1.0;  // entered cells start unknown
        continue;
      }
      const CellState sa = a.Cell({ax, ay});
      layer_mismatch += sb.free != sa.free || sb.static_occ != sa.static_occ ||
                        sb.dynamic != sa.dynamic || sb.mean_velocity != sa.mean_velocity;
      ++compared;
      nonempty += sa.unknown < 1.0;
    }
  }
  CHECK(center_mismatch == 0);
  CHECK(layer_mismatch == 0);
  CHECK(entered_not_unknown == 0);
  CHECK(compared > 0);
  CHECK(nonempty > 10);  // the comparison covers cells with content
}

TEST_CASE("masses, weights and particle count stay valid over random detection sets",
          "[filter][grid][property]") {
  const std::uint64_t seed = GENERATE(range(1, 13));
  const WeightMode mode = GENERATE(WeightMode::kPosition, WeightMode::kVelocity, WeightMode::kDual);
  FilterParams fp;
  fp.mode = mode;
  fp.num_particles = 4000;
  fp.num_birth = 400;
  DynamicGrid g(fp, seed);
  Pose2 ego;
  CounterRng rng(seed, RngPurpose::kTest, 1000, 0);
  ego.position = {rng.Uniform(-1000.0, 1000.0), rng.Uniform(-1000.0, 1000.0)};
  ego.yaw = rng.Uniform(-0.3, 0.3);
  for (int step = 0; step < 8; ++step) {
    ego.position += Vector2(rng.Uniform(0.0, 2.0), rng.Uniform(-0.3, 0.3));
    const auto cov = Sensors(ego);
    const auto z = RandomDetections(ego, seed, step, cov);
    g.Update({ego, {20, 0}}, z, cov, 0.05);
    const ParticleSet& p = g.particles();
    REQUIRE(p.size() == static_cast<std::size_t>(fp.num_particles));
    // Violations are counted (one assertion per cycle keeps the suite fast).
    int bad_particles = 0, bad_cells = 0;
    const auto nonneg = [](double v) { return std::isfinite(v) && v >= 0.0; };
    for (std::size_t i = 0; i < p.size(); ++i) {
      const bool ok = std::isfinite(p.x[i]) && std::isfinite(p.y[i]) && std::isfinite(p.vx[i]) &&
                      std::isfinite(p.vy[i]) && nonneg(p.weight[i]) && nonneg(p.w_position[i]) &&
                      nonneg(p.w_velocity[i]);
      bad_particles += !ok;
    }
    double total_dynamic = 0.0;
    for (int y = 0; y < g.cells_y(); ++y) {
      for (int x = 0; x < g.cells_x(); ++x) {
        const CellState c = g.Cell({x, y});
        bool ok = true;
        for (double m : {c.free, c.static_occ, c.dynamic, c.unknown}) {
          ok = ok && nonneg(m) && m <= 1.0;
        }
        ok = ok && std::abs(c.free + c.static_occ + c.dynamic + c.unknown - 1.0) < 1e-12;
        ok = ok && c.free + c.static_occ + c.dynamic <= 1.0 + 1e-12;
        ok = ok && c.velocity_cov.allFinite() && c.velocity_cov(0, 0) >= 0.0 &&
             c.velocity_cov(1, 1) >= 0.0 && c.mean_velocity.allFinite();
        bad_cells += !ok;
        total_dynamic += c.dynamic;
      }
    }
    INFO("seed " << seed << " mode " << ToString(mode) << " step " << step);
    CHECK(bad_particles == 0);
    CHECK(bad_cells == 0);
    // Not vacuous: from the second cycle on (new-born mass is reported as dynamic only once its
    // particles have survived a cycle) the grid holds dynamic mass.
    if (!z.empty() && step > 0) CHECK(total_dynamic > 0.0);
  }
}

TEST_CASE("free space lies in front of detections, unknown behind and outside the field of view",
          "[filter][grid]") {
  FilterParams fp;
  DynamicGrid g(fp, 3);
  Pose2 ego;
  const SensorCoverage cov = ForwardRadar(ego);
  const std::vector<Measurement> z = {Detect({40.0, 0.0}, {0, 0}, cov.origin)};
  g.Update({ego, {0, 0}}, z, std::span<const SensorCoverage>(&cov, 1), 0.05);
  const CellState before = g.Cell(*g.CellOf({20.0, 0.0}));
  const CellState behind = g.Cell(*g.CellOf({60.0, 0.0}));
  const CellState outside = g.Cell(*g.CellOf({-20.0, 0.0}));
  const CellState at = g.Cell(*g.CellOf({40.0, 0.0}));
  CHECK(before.free == Approx(fp.free_mass).margin(1e-9));
  CHECK(before.observed);
  CHECK(behind.unknown == 1.0);
  CHECK(behind.observed);
  CHECK(outside.unknown == 1.0);
  CHECK_FALSE(outside.observed);
  CHECK(at.free < 0.05);
  CHECK(at.static_occ + at.dynamic > 0.5);
}

namespace {

// Particles and cell states after six cycles (with a Reframe after the third when `turn`), as
// doubles, with the calling thread's OpenMP settings.
std::vector<double> GridBits(WeightMode mode, bool turn) {
  FilterParams fp;
  fp.mode = mode;
  fp.num_particles = 20000;  // many particles so both threads get work
  fp.num_birth = 2000;
  DynamicGrid g(fp, 77);
  Pose2 ego;
  for (int step = 0; step < 6; ++step) {
    ego.position.x() += 1.2;
    const auto cov = Sensors(ego);
    g.Update({ego, {24, 0}}, RandomDetections(ego, 77, step, cov), cov, 0.05);
    if (turn && step == 2) g.Reframe(0.1, ego.position);
  }
  std::vector<double> out;
  const ParticleSet& p = g.particles();
  for (std::size_t i = 0; i < p.size(); ++i) {
    out.insert(out.end(),
               {p.x[i], p.y[i], p.vx[i], p.vy[i], p.w_position[i], p.w_velocity[i], p.weight[i]});
  }
  for (int y = 0; y < g.cells_y(); ++y) {
    for (int x = 0; x < g.cells_x(); ++x) {
      const CellState c = g.Cell({x, y});
      out.insert(out.end(),
                 {c.free, c.static_occ, c.dynamic, c.mean_velocity.x(), c.velocity_cov(0, 1)});
    }
  }
  return out;
}

std::size_t Mismatches(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size()) return a.size() + b.size();
  std::size_t m = 0;
  for (std::size_t i = 0; i < a.size(); ++i) m += a[i] != b[i];
  return m;
}

}  // namespace

TEST_CASE("output is bit-identical with 1, 2 and 3 OpenMP threads", "[filter][determinism]") {
  const WeightMode mode = GENERATE(WeightMode::kPosition, WeightMode::kVelocity, WeightMode::kDual);
  const bool turn = GENERATE(false, true);
  const auto run = [&](int threads) {
    omp_set_num_threads(threads);
    return GridBits(mode, turn);
  };
  const int saved = omp_get_max_threads();
  // Three threads split the float kernels' cells and particles at other places again.
  const std::vector<double> one = run(1), two = run(2), three = run(3);
  omp_set_num_threads(saved);
  REQUIRE(!one.empty());
  CHECK(Mismatches(one, two) == 0);
  CHECK(Mismatches(one, three) == 0);
}

// The co-simulation's pattern (cosim/src/cosimulation.cpp): filters updated on the threads of an
// enclosing region, each with omp_set_num_threads(per_filter). The cycle's region binds to its
// own team (with one thread per filter: no region, so nothing binds to the enclosing one).
TEST_CASE("Update from the threads of an enclosing region gives the same bits",
          "[filter][determinism]") {
  const int per_filter = GENERATE(1, 2);
  const int levels = GENERATE(1, 2);  // 1: the filters' regions get one thread; 2: nested teams
  const std::vector<double> plain = [] {
    const int saved = omp_get_max_threads();
    omp_set_num_threads(1);
    auto bits = GridBits(WeightMode::kDual, true);
    omp_set_num_threads(saved);
    return bits;
  }();
  const int saved_levels = omp_get_max_active_levels();
  omp_set_max_active_levels(levels);
  std::vector<double> nested[2];
#pragma omp parallel num_threads(2)
  {
    omp_set_num_threads(per_filter);  // this thread's nested regions only
    nested[omp_get_thread_num()] = GridBits(WeightMode::kDual, true);
  }
  omp_set_max_active_levels(saved_levels);
  INFO("per_filter " << per_filter << ", max active levels " << levels);
  CHECK(Mismatches(plain, nested[0]) == 0);
  CHECK(Mismatches(plain, nested[1]) == 0);
}

TEST_CASE("new-born mass belongs to the last update only, in every path and after a shift",
          "[filter][grid][birth]") {
  const std::uint64_t seed = GENERATE(range(1, 5));
  FilterParams fp;
  fp.num_particles = 4000;
  fp.num_birth = 400;
  DynamicGrid g(fp, seed);
  CHECK(g.NewbornMass() == 0.0);
  Pose2 ego;
  CounterRng rng(seed, RngPurpose::kTest, 2000, 0);
  ego.position = {rng.Uniform(-1000.0, 1000.0), rng.Uniform(-1000.0, 1000.0)};
  const auto detect = [&](int step) {
    const auto cov = Sensors(ego);
    g.Update({ego, {20, 0}}, RandomDetections(ego, seed, step, cov), cov, 0.05);
    // Not vacuous: detections give birth mass.
    REQUIRE(g.NewbornMass() > 0.0);
  };
  const auto nothing = [&] {
    const auto cov = Sensors(ego);
    g.Update({ego, {20, 0}}, {}, cov, 0.05);
    // Without detections there is no birth (a_birth = 0 everywhere): any mass left is an earlier
    // cycle's, in cells the fast path or a shift passed over.
    CHECK(g.NewbornMass() == 0.0);
    CHECK_FALSE(g.CheckInvariants());
  };
  detect(0);
  detect(1);
  nothing();  // in place: fast-path cells
  detect(2);
  ego.position += Vector2(3.2, 1.1);  // a shift by whole cells
  nothing();
  detect(3);
  ego.position += Vector2(5000.0, 0.0);  // beyond the grid: every cell is new
  nothing();
}

TEST_CASE("a shared MeasurementGrid and PredictionNoise give every filter the same cycle",
          "[filter][measurement]") {
  // Three modes with their own Update against three fed one MeasurementGrid and one
  // PredictionNoise per cycle (the co-simulation's way): particles, masses and observed bits equal
  // bit for bit, with the Doppler fit on (the default) and off, while the ego moves by fractions
  // of a cell. The noise is drawn for more particles than the filters have (allowed).
  const bool fit = GENERATE(true, false);
  std::vector<DynamicGrid> own, shared;
  FilterParams base;
  base.num_particles = 4000;
  base.num_birth = 400;
  if (!fit) {
    base.birth_velocity = BirthVelocity::kDoppler;
    base.velocity_likelihood = VelocityLikelihood::kRadial;
  }
  for (WeightMode m : {WeightMode::kPosition, WeightMode::kVelocity, WeightMode::kDual}) {
    FilterParams fp = base;
    fp.mode = m;
    own.emplace_back(fp, 11);
    shared.emplace_back(fp, 11);
  }
  MeasurementGrid mg(base);
  PredictionNoise noise;
  Pose2 ego;
  std::size_t mismatches = 0;
  for (int step = 0; step < 8; ++step) {
    ego.position += Vector2(0.73, 0.11);
    const auto cov = Sensors(ego);
    const auto z = RandomDetections(ego, 13, step, cov);
    mg.Build(ego.position, z, cov);
    noise.Draw(11, static_cast<std::uint64_t>(step), base.num_particles + 77);
    for (std::size_t m = 0; m < own.size(); ++m) {
      own[m].Update({ego, {14.6, 2.2}}, z, cov, 0.05);
      // Every other cycle without the noise: the filter draws its own, the same.
      shared[m].Update({ego, {14.6, 2.2}}, mg, 0.05, step % 3 == 1 ? nullptr : &noise);
      const ParticleSet &a = own[m].particles(), &b = shared[m].particles();
      for (std::size_t i = 0; i < a.size(); ++i)
        mismatches += a.x[i] != b.x[i] || a.y[i] != b.y[i] || a.vx[i] != b.vx[i] ||
                      a.vy[i] != b.vy[i] || a.weight[i] != b.weight[i] ||
                      a.w_position[i] != b.w_position[i] || a.w_velocity[i] != b.w_velocity[i];
      const std::size_t n = static_cast<std::size_t>(own[m].cells_x()) * own[m].cells_y();
      std::vector<float> fa(n), sa(n), da(n), fb(n), sb(n), db(n);
      std::vector<std::uint8_t> oa(n), ob(n);
      own[m].ExportMasses(fa, sa, da, oa);
      shared[m].ExportMasses(fb, sb, db, ob);
      mismatches += fa != fb || sa != sb || da != db || oa != ob;
    }
  }
  CHECK(mismatches == 0);
  // Sanity: the run produced moving mass in every mode (else equality would prove little).
  for (const DynamicGrid& g : shared) {
    double w = 0.0;
    for (float x : g.particles().weight) w += x;
    CHECK(w > 0.0);
  }
}

TEST_CASE("a MeasurementGrid for another geometry or position is refused",
          "[filter][measurement]") {
  FilterParams fp;
  fp.num_particles = 1000;
  fp.num_birth = 100;
  DynamicGrid g(fp, 3);
  Pose2 ego;
  const auto cov = Sensors(ego);
  const auto z = RandomDetections(ego, 3, 0, cov);
  MeasurementGrid never(fp);
  CHECK_THROWS_AS(g.Update({ego, {0, 0}}, never, 0.05), std::invalid_argument);
  FilterParams finer = fp;
  finer.resolution = 0.25;
  MeasurementGrid other(finer);
  other.Build(ego.position, z, cov);
  CHECK_FALSE(other.SharesGeometry(fp));
  CHECK_THROWS_AS(g.Update({ego, {0, 0}}, other, 0.05), std::invalid_argument);
  MeasurementGrid elsewhere(fp);
  elsewhere.Build(ego.position + Vector2(fp.resolution, 0.0), z, cov);  // one cell further
  CHECK_THROWS_AS(g.Update({ego, {0, 0}}, elsewhere, 0.05), std::invalid_argument);
  CHECK(g.step() == 0);  // nothing ran
  MeasurementGrid right(fp);
  {
    right.Build(ego.position, z, cov);
    PredictionNoise wrong;
    wrong.Draw(3, 1, fp.num_particles);  // the next cycle is step 0
    CHECK_THROWS_AS(g.Update({ego, {0, 0}}, right, 0.05, &wrong), std::invalid_argument);
    wrong.Draw(4, 0, fp.num_particles);  // another seed
    CHECK_THROWS_AS(g.Update({ego, {0, 0}}, right, 0.05, &wrong), std::invalid_argument);
    wrong.Draw(3, 0, fp.num_particles - 1);  // too few particles
    CHECK_THROWS_AS(g.Update({ego, {0, 0}}, right, 0.05, &wrong), std::invalid_argument);
    CHECK(g.step() == 0);
  }
  right.Build(ego.position, z, cov);
  FilterParams velocity = fp;
  velocity.mode = WeightMode::kVelocity;  // the weight mode is not geometry
  CHECK(right.SharesGeometry(velocity));
  g.Update({ego, {0, 0}}, right, 0.05);
  CHECK(g.step() == 1);
}

TEST_CASE("ForEachWeightedCellWhere gives the particles of the cells a layer keeps, by CellOf",
          "[filter][grid][property]") {
  // The reference: each weighted particle located with CellOf; consecutive particles in one cell
  // above the threshold form one call. 0.3 m: 1 / r is inexact, so CellOf must share the sort's
  // arithmetic (x * (1 / r)) to agree on cell borders; the ego moves by fractions of a cell.
  const std::uint64_t seed = GENERATE(range(1, 7));
  FilterParams fp;
  fp.resolution = 0.3;
  fp.length_x = 60.0;
  fp.width_y = 30.0;
  fp.num_particles = 3000;
  fp.num_birth = 300;
  DynamicGrid g(fp, seed);
  const std::size_t cells = static_cast<std::size_t>(g.cells_x()) * g.cells_y();
  std::vector<float> fr(cells), st(cells), dyn(cells, 1.0f);
  std::vector<std::uint8_t> seen(cells);
  using Call = std::array<std::int64_t, 3>;  // k, first, last
  std::vector<Call> got;
  const auto record = [&](std::size_t k, std::int64_t first, std::int64_t last) {
    got.push_back({static_cast<std::int64_t>(k), first, last});
  };
  const auto above = [](double threshold) {
    return [threshold](float v) { return v > threshold; };
  };
  g.ForEachWeightedCellWhere(std::span<const float>(dyn), above(0.5), record);  // no particles yet
  CHECK(got.empty());
  Pose2 ego;
  CounterRng rng(seed, RngPurpose::kTest, 2000, 0);
  ego.position = {rng.Uniform(-500.0, 500.0), rng.Uniform(-500.0, 500.0)};
  for (int step = 0; step < 6; ++step) {
    ego.position += Vector2(rng.Uniform(0.0, 1.7), rng.Uniform(-0.4, 0.4));
    const auto cov = Sensors(ego);
    g.Update({ego, {20, 0}}, RandomDetections(ego, seed, step, cov), cov, 0.05);
    g.ExportMasses(fr, st, dyn, seen);
    const ParticleSet& p = g.weighted_particles();
    int differ = 0;
    std::size_t calls = 0;
    // -1: every cell holding particles, so every particle on the grid is in exactly one call.
    // The same cells as bytes (a layer of classes): 1 where the mass is above the threshold.
    std::vector<std::uint8_t> bytes(cells);
    for (const double threshold : {-1.0, 0.3, 0.6}) {
      std::vector<Call> want;
      for (std::int64_t i = 0; i < static_cast<std::int64_t>(g.num_weighted_particles()); ++i) {
        const auto c = g.CellOf({p.x[i], p.y[i]});
        if (!c) continue;
        const std::int64_t k = static_cast<std::int64_t>(c->y) * g.cells_x() + c->x;
        if (!(dyn[static_cast<std::size_t>(k)] > threshold)) continue;
        if (!want.empty() && want.back()[0] == k && want.back()[2] == i)
          ++want.back()[2];
        else
          want.push_back({k, i, i + 1});
      }
      got.clear();
      g.ForEachWeightedCellWhere(std::span<const float>(dyn), above(threshold), record);
      differ += want != got;
      calls += got.size();
      for (std::size_t k = 0; k < cells; ++k) bytes[k] = dyn[k] > threshold ? 1 : 0;
      got.clear();
      g.ForEachWeightedCellWhere(
          std::span<const std::uint8_t>(bytes), [](std::uint8_t b) { return b == 1; }, record);
      differ += want != got;
    }
    INFO("seed " << seed << " step " << step);
    CHECK(differ == 0);
    CHECK(calls > 0);
    CHECK_THROWS_AS(g.ForEachWeightedCellWhere(std::span<const float>(dyn).first(cells - 1),
                                               above(0.5), record),
                    std::invalid_argument);
  }
  g.Reframe(0.1, ego.position);
  CHECK_THROWS_AS(g.ForEachWeightedCellWhere(std::span<const float>(dyn), above(0.5), record),
                  std::logic_error);
}

TEST_CASE("ForEachWeightedCellWhere with ByteIs makes the calls of the plain byte test",
          "[filter][grid][property]") {
  // ByteIs tests 8 bytes per word: the same calls in the same order as a callable v == value, on
  // layers of no kept cell, all, sparse cells and runs of kept cells (across word boundaries and
  // the storage wrap, which the ego's fractional moves shift), with the other bytes often differing
  // from the value in one bit only (bit 7 or bit 0: a carry between bytes would show). 61.5 m at
  // 0.3 m: 205 columns, so rows end in a partial word.
  const std::uint64_t seed = GENERATE(range(1, 5));
  FilterParams fp;
  fp.resolution = 0.3;
  fp.length_x = 61.5;
  fp.width_y = 30.0;
  fp.num_particles = 3000;
  fp.num_birth = 300;
  DynamicGrid g(fp, seed);
  REQUIRE(g.cells_x() % 8 != 0);
  const std::size_t cells = static_cast<std::size_t>(g.cells_x()) * g.cells_y();
  using Call = std::array<std::int64_t, 3>;  // k, first, last
  std::vector<Call> fast, plain;
  const auto into = [](std::vector<Call>& calls) {
    return [&calls](std::size_t k, std::int64_t first, std::int64_t last) {
      calls.push_back({static_cast<std::int64_t>(k), first, last});
    };
  };
  CounterRng rng(seed, RngPurpose::kTest, 2001, 0);
  const auto byte = [&](int lo, int hi) { return static_cast<int>(rng.Uniform(lo, hi + 1.0)); };
  Pose2 ego;
  ego.position = {rng.Uniform(-500.0, 500.0), rng.Uniform(-500.0, 500.0)};
  std::vector<std::uint8_t> layer(cells);
  std::size_t kept_calls = 0;
  for (int step = 0; step < 5; ++step) {
    ego.position += Vector2(rng.Uniform(0.0, 1.7), rng.Uniform(-0.4, 0.4));
    const auto cov = Sensors(ego);
    g.Update({ego, {20, 0}}, RandomDetections(ego, seed, step, cov), cov, 0.05);
    for (const int pattern : {0, 1, 2, 3}) {  // none, all, sparse, runs
      const auto value = static_cast<std::uint8_t>(std::min(byte(0, 255), 255));
      const std::uint8_t near[] = {static_cast<std::uint8_t>(value ^ 0x80),
                                   static_cast<std::uint8_t>(value ^ 0x01)};
      for (std::uint8_t& b : layer) {
        const int r = byte(0, 3);
        b = r < 2 ? near[r] : static_cast<std::uint8_t>(std::min(byte(0, 255), 255));
        if (b == value) b = near[0];
        if (pattern == 1 || (pattern == 2 && rng.Uniform(0.0, 1.0) < 0.05)) b = value;
      }
      if (pattern == 3) {
        for (int run = 0; run < 200; ++run) {
          const auto k0 = static_cast<std::size_t>(rng.Uniform(0.0, static_cast<double>(cells)));
          const std::size_t len = static_cast<std::size_t>(byte(1, 20));
          for (std::size_t k = k0; k < std::min(cells, k0 + len); ++k) layer[k] = value;
        }
      }
      fast.clear();
      plain.clear();
      g.ForEachWeightedCellWhere(std::span<const std::uint8_t>(layer), ByteIs{value}, into(fast));
      g.ForEachWeightedCellWhere(
          std::span<const std::uint8_t>(layer), [value](std::uint8_t b) { return b == value; },
          into(plain));
      INFO("seed " << seed << " step " << step << " pattern " << pattern << " value "
                   << static_cast<int>(value));
      CHECK(fast == plain);
      if (pattern == 0) CHECK(fast.empty());
      if (pattern != 0) CHECK(!fast.empty());
      kept_calls += fast.size();
    }
  }
  CHECK(kept_calls > 0);
}

TEST_CASE("ExportMeanVelocities gives Cell's mean velocities of every cell, as float",
          "[filter][grid][property]") {
  // The ego moves by fractions of a cell each step, so the storage origin wraps in both axes and
  // a logical row spans two storage runs; the reference is Cell() cell by cell.
  const std::uint64_t seed = GENERATE(range(1, 4));
  FilterParams fp;
  fp.length_x = 60.0;
  fp.width_y = 30.0;
  fp.num_particles = 3000;
  fp.num_birth = 300;
  DynamicGrid g(fp, seed);
  const std::size_t cells = static_cast<std::size_t>(g.cells_x()) * g.cells_y();
  std::vector<float> vx(cells, 7.0f), vy(cells, 7.0f);
  g.ExportMeanVelocities(vx, vy);  // before the first Update: no particles, zero means
  CHECK(std::count(vx.begin(), vx.end(), 0.0f) == static_cast<std::ptrdiff_t>(cells));
  Pose2 ego;
  CounterRng rng(seed, RngPurpose::kTest, 2001, 0);
  ego.position = {rng.Uniform(-500.0, 500.0), rng.Uniform(-500.0, 500.0)};
  int moving = 0;  // cells with a mean speed above 0.5 m/s, over all steps
  for (int step = 0; step < 6; ++step) {
    ego.position += Vector2(rng.Uniform(0.0, 1.7), rng.Uniform(-1.0, 1.0));
    const auto cov = Sensors(ego);
    g.Update({ego, {20, 0}}, RandomDetections(ego, seed, step, cov), cov, 0.05);
    g.ExportMeanVelocities(vx, vy);
    int differ = 0;
    for (int y = 0; y < g.cells_y(); ++y) {
      for (int x = 0; x < g.cells_x(); ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * g.cells_x() + x;
        const CellState c = g.Cell({x, y});
        differ += vx[i] != static_cast<float>(c.mean_velocity.x()) ||
                  vy[i] != static_cast<float>(c.mean_velocity.y());
        moving += c.mean_velocity.norm() > 0.5;
      }
    }
    INFO("seed " << seed << " step " << step);
    CHECK(differ == 0);
  }
  CHECK(moving > 0);  // else equality of zeros would prove little
  CHECK_THROWS_AS(g.ExportMeanVelocities(std::span<float>(vx).first(cells - 1), vy),
                  std::invalid_argument);
}

TEST_CASE("an ego beyond kMaxCentre is refused before the grid moves", "[filter][measurement]") {
  // A jump to 1e300 m after the first cycle used to overflow the global cell index (a shift of
  // ~2^63 cells, cleared column by column: a hang); the bound is checked before anything changes.
  FilterParams fp;
  fp.num_particles = 1000;
  fp.num_birth = 100;
  DynamicGrid g(fp, 5);
  Pose2 ego;
  g.Update({ego, {0, 0}}, {}, {}, 0.05);
  REQUIRE(g.step() == 1);
  for (const double far : {1e300, -1e300, 2.0 * FilterParams::kMaxCentre}) {
    Pose2 jump;
    jump.position = Vector2(far, 0.0);
    CHECK_THROWS_AS(g.Update({jump, {0, 0}}, {}, {}, 0.05), std::invalid_argument);
    jump.position = Vector2(0.0, far);
    CHECK_THROWS_AS(g.Update({jump, {0, 0}}, {}, {}, 0.05), std::invalid_argument);
    CHECK_THROWS_AS(g.Reframe(0.1, Vector2(far, 0.0)), std::invalid_argument);
    MeasurementGrid m(fp);
    CHECK_THROWS_AS(m.Build(Vector2(far, 0.0), {}, {}), std::invalid_argument);
  }
  CHECK(g.step() == 1);  // nothing ran
  Pose2 edge;            // the bound itself is accepted
  edge.position = Vector2(FilterParams::kMaxCentre, -FilterParams::kMaxCentre);
  g.Update({edge, {0, 0}}, {}, {}, 0.05);
  CHECK(g.step() == 2);
}
