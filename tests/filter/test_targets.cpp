// Synthetic single targets with exact detections: the three weight modes on the paper's cases.
#include <catch2/catch.hpp>

#include "dualgrid/filter/dynamic_grid.hpp"
#include "synthetic.hpp"

using namespace dualgrid;
using namespace dualgrid::filter;
using namespace dualgrid::filter::testing;

TEST_CASE("the grid's invariants hold after every cycle, in every case and mode",
          "[filter][targets][invariants]") {
  const Case c = GENERATE(Case::kRadial, Case::kTangential, Case::kStatic);
  const WeightMode mode = GENERATE(WeightMode::kPosition, WeightMode::kVelocity, WeightMode::kDual);
  const std::uint64_t seed = GENERATE(1, 2);
  const Trace t = Run(c, mode, seed);
  INFO("case " << static_cast<int>(c) << " mode " << ToString(mode) << " seed " << seed);
  CHECK(t.broken.empty());
  if (!t.broken.empty()) FAIL_CHECK(t.broken.front());
}

TEST_CASE("a target on the radar's line of sight becomes dynamic with the right velocity",
          "[filter][targets]") {
  // Within 1 s (20 cycles; the paper's slowest mode needs 0.92 s to a first track) every mode must
  // show P(dynamic) > 0.6 (the evaluation threshold) in the target's cells, and the particle mean
  // velocity must be within 1 m/s of the truth: 4 % of the speed, while a birth velocity that is
  // not yet selected is off by ~U(-40, 40) m/s tangentially (rms 23 m/s), so an unconverged
  // filter fails this clearly.
  const WeightMode mode = GENERATE(WeightMode::kPosition, WeightMode::kVelocity, WeightMode::kDual);
  const std::uint64_t seed = GENERATE(1, 2, 3);
  const Trace t = Run(Case::kRadial, mode, seed);
  for (int k = 20; k < 60; ++k) {
    INFO("mode " << ToString(mode) << " seed " << seed << " cycle " << k);
    REQUIRE(t.views[k].max_dynamic > 0.6);
    REQUIRE(t.views[k].has_particles);
  }
  CHECK(MeanVelocityError(t, 20, 60) < 1.0);
}

TEST_CASE("a static box stays static in every mode", "[filter][targets]") {
  // After 0.5 s the box's cells must be static (P(static) > 0.6) and never reach the dynamic
  // threshold; births there carry U(-40, 40) m/s tangential velocities, so a filter that lets
  // them keep their mass fails the dynamic bound.
  const WeightMode mode = GENERATE(WeightMode::kPosition, WeightMode::kVelocity, WeightMode::kDual);
  const std::uint64_t seed = GENERATE(1, 2, 3);
  const Trace t = Run(Case::kStatic, mode, seed);
  for (int k = 0; k < 60; ++k) {
    INFO("mode " << ToString(mode) << " seed " << seed << " cycle " << k);
    REQUIRE(t.views[k].max_dynamic < 0.6);
    if (k >= 10) REQUIRE(t.views[k].max_static > 0.6);
  }
}

TEST_CASE("a tangential target is tracked by position and dual weights, not by velocity weights",
          "[filter][targets]") {
  // The paper's central claim (Sec. IV, highway "object 3"). The compensated Doppler is ~0, so
  // eq. (8) rewards particles near v = 0 and the static hypothesis, while eq. (7) ignores the
  // Doppler. Over the last 2 s (cycles 20-60):
  //  - position and dual: mean velocity error < 4 m/s (16 % of 25 m/s; the lateral position of
  //    the detections constrains the velocity only through cell-to-cell consistency, and the box
  //    margin averages in lagging particles) and P(dynamic) > 0.6 somewhere on the target;
  //  - velocity: error > 6 m/s and at least twice the dual error, i.e. markedly worse.
  // The paper's eq. (8) form of f_v (velocity_likelihood: vector; the default radial form removes
  // the failure: test_switches.cpp).
  const std::uint64_t seed = GENERATE(1, 2, 3, 4);
  const auto run = [&](WeightMode mode) {
    FilterParams fp;
    fp.mode = mode;
    // Doppler births (tangential part uniform): the default doppler_fit births take the
    // tangential velocity from the neighbours' Dopplers and remove this failure as well.
    fp.birth_velocity = BirthVelocity::kDoppler;
    fp.velocity_likelihood = VelocityLikelihood::kVector;
    return Run(Case::kTangential, fp, seed);
  };
  const Trace pos = run(WeightMode::kPosition);
  const Trace vel = run(WeightMode::kVelocity);
  const Trace dual = run(WeightMode::kDual);
  const double e_pos = MeanVelocityError(pos, 20, 60);
  const double e_vel = MeanVelocityError(vel, 20, 60);
  const double e_dual = MeanVelocityError(dual, 20, 60);
  INFO("seed " << seed << " errors position " << e_pos << " velocity " << e_vel << " dual "
               << e_dual);
  CHECK(e_pos < 4.0);
  CHECK(e_dual < 4.0);
  CHECK(e_vel > 6.0);
  CHECK(e_vel > 2.0 * e_dual);
  for (int k = 20; k < 60; ++k) {
    REQUIRE(pos.views[k].max_dynamic > 0.6);
    REQUIRE(dual.views[k].max_dynamic > 0.6);
  }
}
