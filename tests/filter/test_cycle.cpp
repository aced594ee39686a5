// The per-cycle factors scaled to the cycle's dt (docs/algorithm.md, "Asynchronous sensors").
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <vector>

#include "dualgrid/filter/dynamic_grid.hpp"

using namespace dualgrid;
using namespace dualgrid::filter;

namespace {

bool SameBytes(const FilterParams& a, const FilterParams& b) {
  const double x[] = {a.persistence, a.static_persistence, a.free_decay, a.decay_eps,
                      a.birth_probability};
  const double y[] = {b.persistence, b.static_persistence, b.free_decay, b.decay_eps,
                      b.birth_probability};
  return std::memcmp(x, y, sizeof x) == 0;
}

}  // namespace

TEST_CASE("ForCycle keeps the factors bit for bit at the reference cycle") {
  FilterParams p;
  p.cycle = 0.05;
  CHECK(SameBytes(ForCycle(p, 0.05), p));
  // SUMO's step times carry rounding: 0.15 - 0.1 is not 0.05 in binary.
  CHECK(0.15 - 0.1 != 0.05);
  CHECK(SameBytes(ForCycle(p, 0.15 - 0.1), p));
  p.cycle = 0.1;
  CHECK(SameBytes(ForCycle(p, 0.30000000000000004 - 0.2), p));
}

TEST_CASE("ForCycle scales each factor as a survival probability per reference cycle") {
  FilterParams p;
  const FilterParams two = ForCycle(p, 2.0 * p.cycle);
  CHECK(two.persistence == Approx(p.persistence * p.persistence).epsilon(1e-14));
  CHECK(two.static_persistence ==
        Approx(p.static_persistence * p.static_persistence).epsilon(1e-14));
  CHECK(two.free_decay == Approx(p.free_decay * p.free_decay).epsilon(1e-14));
  CHECK(1.0 - two.decay_eps == Approx((1.0 - p.decay_eps) * (1.0 - p.decay_eps)).epsilon(1e-14));
  // Two cycles without a birth: (1 - p_B)^2.
  CHECK(1.0 - two.birth_probability ==
        Approx((1.0 - p.birth_probability) * (1.0 - p.birth_probability)).epsilon(1e-14));
  // Cycles of dt1 and dt2 compose to one of dt1 + dt2 (a 13 Hz radar: 0.019 s and 0.056 s).
  const FilterParams a = ForCycle(p, 0.019), b = ForCycle(p, 0.056), ab = ForCycle(p, 0.075);
  CHECK(a.persistence * b.persistence == Approx(ab.persistence).epsilon(1e-14));
  CHECK((1.0 - a.birth_probability) * (1.0 - b.birth_probability) ==
        Approx(1.0 - ab.birth_probability).epsilon(1e-14));
  // dt = 0 keeps everything.
  const FilterParams zero = ForCycle(p, 0.0);
  CHECK(zero.persistence == 1.0);
  CHECK(zero.free_decay == 1.0);
  CHECK(zero.decay_eps == 0.0);
  CHECK(zero.birth_probability == 0.0);
  // Other fields untouched.
  CHECK(a.sigma_f == p.sigma_f);
  CHECK(a.num_birth == p.num_birth);
}

TEST_CASE("two half cycles decay free space as one full cycle does") {
  FilterParams p;
  p.length_x = 40.0;
  p.width_y = 40.0;
  p.num_particles = 2000;
  p.num_birth = 200;
  const Position sensor(0.0, 0.0);
  const std::vector<Measurement> z = {{Position(15.0, 0.0), Velocity::Zero(), sensor}};
  const std::vector<SensorCoverage> cov = {{sensor, 0.0, 0.5, 0.5, 19.0}};
  const EgoInput ego{{Position::Zero(), 0.0}, Velocity::Zero()};
  DynamicGrid half(p, 3), full(p, 3);
  for (DynamicGrid* g : {&half, &full}) g->Update(ego, z, cov, p.cycle);
  // A cell on the ray, in front of the detection (bearing 1.2 deg: inside the detection's
  // bearing bins, so the ray's free mass, not the no-return one).
  const auto cell = full.CellOf(Position(12.25, 0.25));
  REQUIRE(cell);
  const double f0 = full.Cell(*cell).free;
  REQUIRE(f0 > p.free_mass_no_return);
  // No sensor scans: the free mass only decays.
  half.Update(ego, {}, {}, 0.5 * p.cycle);
  half.Update(ego, {}, {}, 0.5 * p.cycle);
  full.Update(ego, {}, {}, p.cycle);
  CHECK(full.Cell(*cell).free == Approx(p.free_decay * f0).epsilon(1e-12));
  CHECK(half.Cell(*cell).free == Approx(full.Cell(*cell).free).epsilon(1e-12));
}
