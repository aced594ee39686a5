// The switches of FilterParams (docs/algorithm.md, "Switches"): each one changes what it says and
// keeps the grid's invariants.
#include <catch2/catch.hpp>

#include <cmath>
#include <string>
#include <vector>

#include "dualgrid/filter/dynamic_grid.hpp"
#include "synthetic.hpp"

using namespace dualgrid;
using namespace dualgrid::filter;
using namespace dualgrid::filter::testing;

namespace {

constexpr WeightMode kModes[] = {WeightMode::kPosition, WeightMode::kVelocity, WeightMode::kDual};

// Max P(dynamic) on the target over cycles [from, to).
double MaxDynamic(const Trace& t, int from, int to) {
  double m = 0.0;
  for (int k = from; k < to; ++k) m = std::max(m, t.views[k].max_dynamic);
  return m;
}

}  // namespace

TEST_CASE("every combination of switches keeps the grid's invariants",
          "[filter][switches][invariants]") {
  // 16 combinations x 3 modes x 3 cases, 30 cycles each (short, but past the first births,
  // resamplings and the static decision).
  const int combo = GENERATE(range(0, 16));
  FilterParams fp;
  fp.num_particles = 4000;
  fp.num_birth = 400;
  fp.birth_velocity = combo & 1 ? BirthVelocity::kUniform : BirthVelocity::kDoppler;
  fp.zero_likelihood = combo & 2 ? ZeroLikelihood::kLiteral : ZeroLikelihood::kKeepPrediction;
  fp.velocity_likelihood = combo & 4 ? VelocityLikelihood::kRadial : VelocityLikelihood::kVector;
  fp.normalisation = combo & 8 ? Normalisation::kLiteral : Normalisation::kPerCell;
  for (const WeightMode mode : kModes) {
    for (const Case c : {Case::kRadial, Case::kTangential, Case::kStatic}) {
      fp.mode = mode;
      // The last 10 cycles without detections exercise the zero-likelihood branch.
      const Trace t = Run(c, fp, 1, 30, 20);
      INFO("combination " << combo << " mode " << ToString(mode) << " case "
                          << static_cast<int>(c));
      CHECK(t.broken.empty());
      if (!t.broken.empty()) FAIL_CHECK(t.broken.front());
    }
  }
}

TEST_CASE("uniform births carry no Doppler, Doppler births carry it", "[filter][switches]") {
  // One cycle on the radial target (compensated radial speed 25 m/s along +x): after the first
  // resampling every particle is a new-born one. Doppler births: radial component 25 m/s +
  // N(0, 0.5^2), so the mean vx is within 0.5 m/s of 25. Uniform births: velocity uniform in the
  // disc |v| <= 50 m/s (max_speed): each component has mean 0 and standard deviation 50 / 2 =
  // 25 m/s, so over >= 1,000 particles the mean is within 5 standard errors (5 x 25 /
  // sqrt(1000) = 4 m/s) of 0 — far from 25 — and no speed exceeds max_speed.
  for (const BirthVelocity bv : {BirthVelocity::kDoppler, BirthVelocity::kUniform}) {
    FilterParams fp;
    fp.birth_velocity = bv;
    DynamicGrid g(fp, 7);
    const Pose2 ego;
    const SensorCoverage cov = ForwardRadar(ego);
    std::vector<Measurement> z;
    const OrientedBox box{{20.0, 0.3}, 0.0, 4.5, 1.8};
    for (const Position& p : NearFacePoints(box, cov.origin, 1.0, 0.5))
      z.push_back(Detect(p, {25.0, 0.0}, cov.origin));
    g.Update({ego, Velocity::Zero()}, z, std::span<const SensorCoverage>(&cov, 1), 0.05);
    const ParticleSet& p = g.particles();
    double sum_vx = 0.0, max_speed = 0.0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      sum_vx += p.vx[i];
      max_speed = std::max(max_speed, std::hypot(double{p.vx[i]}, double{p.vy[i]}));
    }
    const double mean_vx = sum_vx / static_cast<double>(p.size());
    INFO("birth_velocity " << ToString(bv) << " mean vx " << mean_vx);
    CHECK(max_speed <= fp.max_speed * (1.0 + 1e-6));
    if (bv == BirthVelocity::kDoppler) {
      CHECK(std::abs(mean_vx - 25.0) < 0.5);
    } else {
      CHECK(std::abs(mean_vx) < 4.0);
    }
  }
}

TEST_CASE("literal eq. (7) drops the occupied mass of a missed target, the fall-back keeps it",
          "[filter][switches]") {
  // Position mode on the radial target: tracked after 1 s, then 0.25 s (5 cycles) observed
  // without any detection. Eq. (7) as printed gives every particle and the static hypothesis
  // weight 0: the cells' occupied mass becomes unknown, P(dynamic) = 0 exactly from the first
  // silent cycle. The fall-back keeps the predicted split: the dynamic mass only fades with the
  // free evidence (Dempster), so the first silent cycle still shows a clear part of it.
  FilterParams fp;
  fp.mode = WeightMode::kPosition;
  fp.zero_likelihood = ZeroLikelihood::kLiteral;
  const Trace literal = Run(Case::kRadial, fp, 1, 25, 20);
  fp.zero_likelihood = ZeroLikelihood::kKeepPrediction;
  const Trace kept = Run(Case::kRadial, fp, 1, 25, 20);
  REQUIRE(MaxDynamic(literal, 15, 20) > 0.6);  // tracked before the silence
  REQUIRE(MaxDynamic(kept, 15, 20) > 0.6);
  CHECK(MaxDynamic(literal, 20, 25) == 0.0);
  CHECK(kept.views[20].max_dynamic > 0.1);
}

TEST_CASE("the radial likelihood lets velocity weights track a tangential target",
          "[filter][switches]") {
  // The tangential case of test_targets.cpp (compensated Doppler ~ 0 while the car drives at
  // 25 m/s): with eq. (8)'s vector form, velocity weights favour v ~ 0 (error > 6 m/s there). The
  // radial form compares only the line-of-sight component, which the true velocity matches (0),
  // so the particle velocities are constrained by position consistency as in position mode:
  // the same 4 m/s bound as position and dual weights there.
  const std::uint64_t seed = GENERATE(1, 2, 3, 4);
  FilterParams fp;
  fp.mode = WeightMode::kVelocity;
  fp.birth_velocity = BirthVelocity::kDoppler;  // not the default fit: eq. (8) alone decides
  fp.velocity_likelihood = VelocityLikelihood::kRadial;
  const Trace radial = Run(Case::kTangential, fp, seed);
  fp.velocity_likelihood = VelocityLikelihood::kVector;
  const Trace vector = Run(Case::kTangential, fp, seed);
  const double e_radial = MeanVelocityError(radial, 20, 60);
  const double e_vector = MeanVelocityError(vector, 20, 60);
  INFO("seed " << seed << " velocity-mode error: radial " << e_radial << ", vector " << e_vector);
  CHECK(e_radial < 4.0);
  CHECK(e_vector > 6.0);
}

TEST_CASE("doppler_fit births let even eq. (8)'s vector form track a tangential target",
          "[filter][switches]") {
  // The tangential case above, vector likelihood, but the default births: the detections on the
  // car's near face see it along spread lines of sight, so their Doppler fit gives the tangential
  // velocity and births carry it; eq. (8) then rewards particles near that whole vector. The
  // same 4 m/s bound as position and dual weights, where Doppler births give > 6 m/s.
  const std::uint64_t seed = GENERATE(1, 2, 3, 4);
  FilterParams fp;
  fp.mode = WeightMode::kVelocity;
  fp.velocity_likelihood = VelocityLikelihood::kVector;
  REQUIRE(fp.birth_velocity == BirthVelocity::kDopplerFit);
  const double e_fit = MeanVelocityError(Run(Case::kTangential, fp, seed), 20, 60);
  fp.birth_velocity = BirthVelocity::kDoppler;
  const double e_doppler = MeanVelocityError(Run(Case::kTangential, fp, seed), 20, 60);
  INFO("seed " << seed << " velocity-mode error: doppler_fit births " << e_fit
               << ", doppler births " << e_doppler);
  CHECK(e_fit < 4.0);
  CHECK(e_doppler > 6.0);
}

TEST_CASE("the paper preset separates static from moving targets", "[filter][switches]") {
  // Every switch at its literal reading (uniform births, literal eq. 7, vector eq. 8, literal
  // eqs. 9-12): the static box must never reach the dynamic threshold and must become static; a
  // target moving along the line of sight must reach P(dynamic) > 0.6 within the 3 s run in
  // every mode (uniform births find 25 m/s only by chance, so later than the 1 s of the default).
  const std::optional<FilterParams> paper = Preset("paper");
  REQUIRE(paper);
  for (const WeightMode mode : kModes) {
    FilterParams fp = *paper;
    fp.mode = mode;
    const Trace st = Run(Case::kStatic, fp, 1);
    const Trace rad = Run(Case::kRadial, fp, 1);
    INFO("mode " << ToString(mode) << " static max dynamic " << MaxDynamic(st, 0, 60)
                 << ", radial max dynamic " << MaxDynamic(rad, 0, 60) << ", static at end "
                 << st.views[59].max_static);
    CHECK(MaxDynamic(st, 0, 60) < 0.6);
    CHECK(st.views[59].max_static > 0.6);
    CHECK(MaxDynamic(rad, 20, 60) > 0.6);
  }
}

TEST_CASE("the Doppler-fit switches keep the grid's invariants", "[filter][switches][invariants]") {
  // doppler_fit births and the radial_fit likelihood, alone and together, in every mode and case
  // (the last 10 cycles without detections: no fit at all).
  for (int combo = 1; combo < 4; ++combo) {
    FilterParams fp;
    fp.num_particles = 4000;
    fp.num_birth = 400;
    fp.birth_velocity = combo & 1 ? BirthVelocity::kDopplerFit : BirthVelocity::kDoppler;
    fp.velocity_likelihood =
        combo & 2 ? VelocityLikelihood::kRadialFit : VelocityLikelihood::kRadial;
    for (const WeightMode mode : kModes) {
      for (const Case c : {Case::kRadial, Case::kTangential, Case::kStatic}) {
        fp.mode = mode;
        const Trace t = Run(c, fp, 1, 30, 20);
        INFO("combination " << combo << " mode " << ToString(mode) << " case "
                            << static_cast<int>(c));
        CHECK(t.broken.empty());
        if (!t.broken.empty()) FAIL_CHECK(t.broken.front());
      }
    }
  }
}

TEST_CASE("doppler_fit births carry the velocity that their neighbours' Doppler fits",
          "[filter][switches]") {
  // A car crossing 23 m ahead of the forward radar at 15 m/s (vy); its near (rear) face gives
  // 3 exact detections 0.5 m apart, whose lines of sight spread by +-1.4 deg (|v_r| <= 0.4 m/s).
  // One cycle, so every particle is new-born. Doppler births draw the tangential part (~vy)
  // uniformly in +-40 m/s: a share 6 / 80 = 0.075 falls within 3 m/s of the truth. doppler_fit
  // draws it from the fit for 75 % of births (birth_fit_uniform_share 0.25): to exact Dopplers
  // the fit's spread is the noise floor over the spread of the lines of sight,
  // 0.1 m/s / sqrt(2 (0.5 / 20.75)^2) = 2.9 m/s, and with the radial birth noise (0.5 m/s) a
  // share 0.69 of those lands within 3 m/s: 0.75 * 0.69 + 0.25 * 0.075 = 0.54 in all. The births
  // (1,000, resampled to 10,000) have a binomial standard error of about 0.016: the bounds 0.15
  // and 0.45 are more than 4 of them away.
  const OrientedBox box{{25.0, 0.0}, 0.0, 4.5, 1.8};
  const Velocity truth{0.0, 15.0};
  for (const BirthVelocity bv : {BirthVelocity::kDoppler, BirthVelocity::kDopplerFit}) {
    FilterParams fp;
    fp.birth_velocity = bv;
    DynamicGrid g(fp, 11);
    const Pose2 ego;
    const SensorCoverage cov = ForwardRadar(ego);
    std::vector<Measurement> z;
    for (const Position& p : NearFacePoints(box, cov.origin, 1.0, 0.5))
      z.push_back(Detect(p, truth, cov.origin));
    g.Update({ego, Velocity::Zero()}, z, std::span<const SensorCoverage>(&cov, 1), 0.05);
    const ParticleSet& p = g.particles();
    int near = 0, total = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (p.weight[i] <= 0.0) continue;
      ++total;
      near += std::hypot(p.vx[i] - truth.x(), p.vy[i] - truth.y()) < 3.0;
    }
    REQUIRE(total >= 1000);
    const double share = static_cast<double>(near) / total;
    INFO("birth_velocity " << ToString(bv) << ": " << near << " of " << total
                           << " particles within 3 m/s");
    if (bv == BirthVelocity::kDoppler) {
      CHECK(share < 0.15);
    } else {
      CHECK(share > 0.45);
    }
  }
}

TEST_CASE("the radial_fit likelihood concentrates the weight on the right tangential velocity",
          "[filter][switches]") {
  // The crossing car of the test above, now over 6 cycles, with Doppler births in both runs so
  // that only eq. (8) differs. The radial likelihood cannot tell tangential velocities apart
  // (all have v . u = v_r); they separate only as their positions drift off the detections.
  // radial_fit also weighs the tangential part against the fit (here ~1 m/s wide), so a
  // particle 3 m/s off loses a factor exp(-9 / (2 (1 + 1))) ~ 0.1 per cycle: the weight share
  // within 3 m/s of the truth grows faster than under the radial likelihood, in every seed.
  const std::uint64_t seed = GENERATE(1, 2, 3);
  const Velocity truth{0.0, 15.0};
  double share[2] = {0.0, 0.0};
  for (int fit = 0; fit < 2; ++fit) {
    FilterParams fp;
    fp.mode = WeightMode::kVelocity;
    fp.birth_velocity = BirthVelocity::kDoppler;
    fp.velocity_likelihood = fit ? VelocityLikelihood::kRadialFit : VelocityLikelihood::kRadial;
    DynamicGrid g(fp, seed);
    const Pose2 ego;
    const SensorCoverage cov = ForwardRadar(ego);
    for (int k = 0; k < 6; ++k) {
      const OrientedBox box{{25.0, truth.y() * 0.05 * k}, 0.0, 4.5, 1.8};
      std::vector<Measurement> z;
      for (const Position& p : NearFacePoints(box, cov.origin, 1.0, 0.5))
        z.push_back(Detect(p, truth, cov.origin));
      g.Update({ego, Velocity::Zero()}, z, std::span<const SensorCoverage>(&cov, 1), 0.05);
    }
    const ParticleSet& p = g.particles();
    double near = 0.0, total = 0.0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      total += p.weight[i];
      if (std::hypot(p.vx[i] - truth.x(), p.vy[i] - truth.y()) < 3.0) near += p.weight[i];
    }
    REQUIRE(total > 0.0);
    share[fit] = near / total;
  }
  INFO("seed " << seed << ": weight within 3 m/s after 6 cycles, radial " << share[0]
               << ", radial_fit " << share[1]);
  CHECK(share[1] > 1.5 * share[0]);
  CHECK(share[1] > 0.3);
}

TEST_CASE("radial_fit keeps a parked box static", "[filter][switches]") {
  // A static object's Dopplers fit v = 0: the tangential term is 0 for the static hypothesis and
  // the decision of the paper-preset test above holds unchanged.
  FilterParams fp;
  fp.velocity_likelihood = VelocityLikelihood::kRadialFit;
  fp.birth_velocity = BirthVelocity::kDopplerFit;
  for (const WeightMode mode : kModes) {
    fp.mode = mode;
    const Trace st = Run(Case::kStatic, fp, 1);
    INFO("mode " << ToString(mode));
    CHECK(MaxDynamic(st, 0, 60) < 0.6);
    CHECK(st.views[59].max_static > 0.6);
  }
}
