// The float cycle (issue 37) against the double cycle it replaced (tests/filter/reference: the
// filter of commit 27d8ca3 in namespace filter_ref) on the synthetic cases. docs/algorithm.md,
// "Float state", derives the bounds used here.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "dualgrid/filter/dynamic_grid.hpp"
#include "dualgrid/filter/simd.hpp"
#include "reference/dynamic_grid.hpp"
#include "synthetic.hpp"

using namespace dualgrid;
using namespace dualgrid::filter;
using namespace dualgrid::filter::testing;

namespace {

struct Masses {
  std::vector<float> free, static_occ, dynamic;
  std::vector<std::uint8_t> observed;
};

template <typename Grid>
Masses Export(const Grid& g) {
  const std::size_t n = static_cast<std::size_t>(g.cells_x()) * g.cells_y();
  Masses m{std::vector<float>(n), std::vector<float>(n), std::vector<float>(n),
           std::vector<std::uint8_t>(n)};
  g.ExportMasses(m.free, m.static_occ, m.dynamic, m.observed);
  return m;
}

// Largest particle count of a cell of the reference's weighted particles (after the last update).
int MaxPerCell(const filter_ref::DynamicGrid& g) {
  const auto& p = g.weighted_particles();
  std::vector<int> count(static_cast<std::size_t>(g.cells_x()) * g.cells_y(), 0);
  int most = 0;
  for (std::size_t i = 0; i < g.num_weighted_particles(); ++i) {
    const auto c = g.CellOf({p.x[i], p.y[i]});
    if (c) most = std::max(most, ++count[static_cast<std::size_t>(c->y) * g.cells_x() + c->x]);
  }
  return most;
}

}  // namespace

TEST_CASE("one float cycle stays within float rounding of the double cycle", "[filter][float]") {
  const Case c = GENERATE(Case::kRadial, Case::kTangential, Case::kStatic);
  const WeightMode mode = GENERATE(WeightMode::kPosition, WeightMode::kVelocity, WeightMode::kDual);
  FilterParams fp;
  fp.mode = mode;
  // The first cycles of a run, before resampling has compounded anything: cycle 0 weighs the
  // zero-weight initial particles and the measurement, cycle 1 the births of cycle 0.
  DynamicGrid f(fp, 3);
  filter_ref::DynamicGrid d(fp, 3);
  double worst = 0.0;
  int n_cell = 0;
  for (int k = 0; k < 2; ++k) {
    // Same inputs as synthetic.hpp's Run (one cycle at a time).
    Pose2 ego;
    OrientedBox box{{20.0 + 25.0 * 0.05 * k, 0.3}, 0.0, 4.5, 1.8};
    const SensorCoverage cov = ForwardRadar(ego);
    std::vector<Measurement> z;
    const Velocity v = c == Case::kStatic ? Velocity(0, 0) : Velocity(25, 0);
    for (const Position& p : NearFacePoints(box, cov.origin, 1.0, 0.5))
      z.push_back(Detect(p, v, cov.origin));
    f.Update({ego, {0, 0}}, z, std::span<const SensorCoverage>(&cov, 1), 0.05);
    d.Update({ego, {0, 0}}, z, std::span<const SensorCoverage>(&cov, 1), 0.05);
    const Masses a = Export(f), b = Export(d);
    for (std::size_t i = 0; i < a.free.size(); ++i) {
      worst = std::max({worst, std::abs(double(a.free[i]) - b.free[i]),
                        std::abs(double(a.static_occ[i]) - b.static_occ[i]),
                        std::abs(double(a.dynamic[i]) - b.dynamic[i])});
    }
    n_cell = std::max(n_cell, MaxPerCell(d));
  }
  // Bound (docs/algorithm.md, "Float state"): a mass <= 1 comes out of float weights that pass
  // through ~40 rounded operations each (two exps of <= 2 ulp included) and float sums over at
  // most n_cell particles of a cell (each adds <= 2^-24 of the running sum), then the export's
  // rounding to float: |error| <= (n_cell + 64) 2^-24. Measured: <= 1.5e-7 (n_cell ~500).
  const double bound = (n_cell + 64) * 0x1p-24;
  INFO("case " << int(c) << " mode " << int(mode) << ": worst " << worst << ", bound " << bound);
  CHECK(worst <= bound);
  CHECK(n_cell > 0);
}

TEST_CASE("float and double cycles differ by less than a change of seed", "[filter][float]") {
  const Case c = GENERATE(Case::kRadial, Case::kTangential, Case::kStatic);
  const WeightMode mode = GENERATE(WeightMode::kPosition, WeightMode::kVelocity, WeightMode::kDual);
  FilterParams fp;
  fp.mode = mode;
  const auto summary = [](const Trace& t) {
    double dyn = 0, st = 0, mass = 0, verr = 0;
    for (int k = 20; k < 60; ++k) {
      dyn += t.views[k].max_dynamic / 40;
      st += t.views[k].max_static / 40;
      mass += t.views[k].particle_mass / 40;
      verr += t.views[k].mean_velocity.norm() / 40;
    }
    return std::array<double, 4>{dyn, st, mass, verr};
  };
  std::vector<std::array<double, 4>> seeds;
  for (std::uint64_t s = 1; s <= 5; ++s)
    seeds.push_back(summary(Run<filter_ref::DynamicGrid>(c, fp, s)));
  const auto fl = summary(Run(c, fp, 1));
  // The float cycle draws the same noise but its weights differ in the last bits, so from the
  // first resampling on some particles are copied from a neighbour instead: after a few cycles a
  // run is another Monte Carlo sample of the same filter. Bound: the float run's summary lies
  // within 4 standard deviations of the double runs' spread over seeds (the sd of a new draw
  // about the 5 seeds' mean is sd sqrt(1 + 1/5)); 1e-6 absolute for quantities every seed gives
  // alike (e.g. no static mass on a moving target). Measured: <= 1.9 sd.
  for (int q = 0; q < 4; ++q) {
    double mean = 0, var = 0;
    for (const auto& s : seeds) mean += s[q] / 5;
    for (const auto& s : seeds) var += (s[q] - mean) * (s[q] - mean) / 4;
    const double bound = 4.0 * std::sqrt(var * (1.0 + 1.0 / 5)) + 1e-6;
    INFO("case " << int(c) << " mode " << int(mode) << " quantity " << q << ": float " << fl[q]
                 << ", double mean " << mean << ", bound " << bound);
    CHECK(std::abs(fl[q] - mean) <= bound);
  }
}

TEST_CASE("the filter's SIMD target is the pinned one", "[filter][float][determinism]") {
  // One static target per build: results do not depend on the CPU (docs/performance.md).
#if defined(__x86_64__)
  CHECK(std::string(SimdTarget()) == "SSE4");
#else
  CHECK(std::string(SimdTarget()).size() > 0);
#endif
}
