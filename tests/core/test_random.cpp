#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "dualgrid/core/random.hpp"

using namespace dualgrid;

TEST_CASE("CounterRng is a pure function of its address", "[core][random]") {
  CounterRng a(7, RngPurpose::kTest, 12, 3), b(7, RngPurpose::kTest, 12, 3);
  for (int i = 0; i < 100; ++i) REQUIRE(a.NextU32() == b.NextU32());
  CounterRng c(7, RngPurpose::kTest, 12, 4), d(7, RngPurpose::kTest, 13, 3),
      e(8, RngPurpose::kTest, 12, 3), f(7, RngPurpose::kTest, 12, 3);
  const auto first = f.NextU32();
  CHECK(c.NextU32() != first);
  CHECK(d.NextU32() != first);
  CHECK(e.NextU32() != first);
}

TEST_CASE("CounterRng moments match the distributions", "[core][random][statistics]") {
  const std::uint64_t seed = GENERATE(1u, 2u, 3u);
  CounterRng rng(seed, RngPurpose::kTest, 0, 0);
  const int n = 200000;
  double su = 0, sn = 0, sn2 = 0, sp = 0;
  for (int i = 0; i < n; ++i) {
    const double u = rng.Uniform();
    REQUIRE(u >= 0.0);
    REQUIRE(u < 1.0);
    su += u;
    const double z = rng.Normal();
    sn += z;
    sn2 += z * z;
  }
  for (int i = 0; i < n / 10; ++i) sp += rng.Poisson(3.5);
  // Tolerances: 5 standard errors of each sample mean.
  CHECK(std::abs(su / n - 0.5) < 5.0 * std::sqrt(1.0 / 12.0 / n));
  CHECK(std::abs(sn / n) < 5.0 / std::sqrt(n));
  CHECK(std::abs(sn2 / n - 1.0) < 5.0 * std::sqrt(2.0 / n));
  CHECK(std::abs(sp / (n / 10) - 3.5) < 5.0 * std::sqrt(3.5 / (n / 10)));
}
