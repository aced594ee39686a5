#include <catch2/catch.hpp>

#include <cmath>
#include <numeric>
#include <vector>

#include "dualgrid/core/random.hpp"
#include "dualgrid/filter/particles.hpp"

using namespace dualgrid;
using namespace dualgrid::filter;

namespace {

ParticleSet RandomParticles(std::size_t n, std::uint64_t seed) {
  ParticleSet p;
  p.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    CounterRng rng(seed, RngPurpose::kTest, 0, static_cast<std::uint32_t>(i));
    p.x[i] = rng.Uniform(-500.0, 500.0);
    p.y[i] = rng.Uniform(-50.0, 50.0);
    p.vx[i] = rng.Uniform(-40.0, 40.0);
    p.vy[i] = rng.Uniform(-40.0, 40.0);
    p.weight[i] = p.w_position[i] = p.w_velocity[i] = rng.Uniform();
  }
  return p;
}

}  // namespace

TEST_CASE("prediction with zero noise is exact constant velocity", "[filter][predict]") {
  const std::uint64_t seed = GENERATE(range(1, 9));
  const double dt = GENERATE(0.0, 0.05, 0.1, 1.3);
  ParticleSet p = RandomParticles(500, seed);
  const ParticleSet before = p;
  PredictParticles(p, dt, 0.0, 0.0, 0.9, seed, 3);
  for (std::size_t i = 0; i < p.size(); ++i) {
    CHECK(p.x[i] == before.x[i] + before.vx[i] * dt);
    CHECK(p.y[i] == before.y[i] + before.vy[i] * dt);
    CHECK(p.vx[i] == before.vx[i]);
    CHECK(p.vy[i] == before.vy[i]);
    CHECK(p.weight[i] == static_cast<float>(before.weight[i] * 0.9));
    CHECK(p.w_position[i] == static_cast<float>(before.w_position[i] * 0.9));
  }
}

TEST_CASE("prediction noise has the configured variance", "[filter][predict]") {
  // Sample variance of n normal draws has relative standard error sqrt(2 / n) = 1 % at n = 20000;
  // 5 standard errors (5 %) bound a correct implementation, a wrong dt scaling (x2) fails.
  const std::uint64_t seed = GENERATE(11, 12, 13);
  const std::size_t n = 20000;
  ParticleSet p;
  p.resize(n);
  const double dt = 0.05, sp = 0.3, sv = 1.5;
  PredictParticles(p, dt, sp, sv, 1.0, seed, 7);
  const auto var = [&](const auto& v) {
    const double m = std::accumulate(v.begin(), v.end(), 0.0) / n;
    double s = 0.0;
    for (double x : v) s += (x - m) * (x - m);
    return s / (n - 1);
  };
  CHECK(var(p.x) == Approx(sp * sp * dt).epsilon(0.05));
  CHECK(var(p.y) == Approx(sp * sp * dt).epsilon(0.05));
  CHECK(var(p.vx) == Approx(sv * sv * dt).epsilon(0.05));
  CHECK(var(p.vy) == Approx(sv * sv * dt).epsilon(0.05));
}

TEST_CASE("exclusive scan is exact for integers and matches a serial sum", "[filter][scan]") {
  const std::size_t n = GENERATE(0, 1, 1000, 16384, 100001);
  std::vector<std::int64_t> in(n);
  for (std::size_t i = 0; i < n; ++i) in[i] = static_cast<std::int64_t>((i * 7919) % 13);
  std::vector<std::int64_t> out(n + 1);
  ExclusiveScan(in, out);
  std::int64_t acc = 0;
  for (std::size_t i = 0; i < n; ++i) {
    REQUIRE(out[i] == acc);
    acc += in[i];
  }
  CHECK(out[n] == acc);
}

TEST_CASE("systematic ranges give each source floor or ceil of its expected copies",
          "[filter][resample]") {
  // Low-variance resampling property: copies of source i are within 1 of n_out w_i / W.
  const std::uint64_t seed = GENERATE(range(1, 21));
  CounterRng rng(seed, RngPurpose::kTest, 1, 0);
  const std::size_t n_src = 1 + static_cast<std::size_t>(rng.Uniform() * 3000);
  const std::size_t n_out = 1 + static_cast<std::size_t>(rng.Uniform() * 5000);
  std::vector<double> w(n_src);
  for (double& x : w) x = rng.Uniform() < 0.3 ? 0.0 : rng.Uniform();
  w[0] += 1e-3;  // total > 0
  std::vector<double> cum(n_src + 1);
  ExclusiveScan(w, cum);
  std::vector<std::int64_t> start(n_src + 1);
  SystematicRanges(cum, n_out, rng.Uniform(), start);
  CHECK(start.front() == 0);
  CHECK(start.back() == static_cast<std::int64_t>(n_out));
  for (std::size_t i = 0; i < n_src; ++i) {
    const std::int64_t copies = start[i + 1] - start[i];
    const double expected = static_cast<double>(n_out) * w[i] / cum.back();
    REQUIRE(copies >= 0);
    // 1e-6 absorbs rounding of the prefix sums when expected is (nearly) an integer.
    REQUIRE(copies >= std::floor(expected - 1e-6));
    REQUIRE(copies <= std::ceil(expected + 1e-6));
    if (w[i] == 0.0) REQUIRE(copies == 0);
  }
}
