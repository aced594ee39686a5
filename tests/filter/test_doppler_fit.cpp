// The measurement grid's fast paths against their definitions, bit for bit: the Doppler fit's
// median (filter/src/doppler_fit.cpp: SelectRank against std::nth_element, MadFloorBound against
// its defining property, RobustDopplerFit against the plain fit of reference/doppler_fit.hpp on
// random neighbourhoods that take every path: the floor, a median near the last one, the
// quickselect, failures, NaN) and the field of view's bearings on SIMD lanes (FastAtan2Lanes).
#include <catch2/catch.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "dualgrid/core/random.hpp"
#include "dualgrid/core/types.hpp"
#include "dualgrid/filter/doppler_fit.hpp"
#include "dualgrid/filter/fast_atan2.hpp"
#include "reference/doppler_fit.hpp"

using namespace dualgrid;
using filter::detail::DopplerFit;
using filter::detail::kFitMaxNeighbours;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double NthElement(std::vector<double> a, int k) {
  std::nth_element(a.begin(), a.begin() + k, a.end());
  return a[k];
}

std::uint64_t Bits(double x) { return std::bit_cast<std::uint64_t>(x); }

// Non-negative values (as residuals are: std::abs), with many ties when `levels` > 0, and some
// infinities when `infinite`.
std::vector<double> Values(CounterRng& rng, int n, int levels, bool infinite) {
  std::vector<double> a(n);
  for (double& x : a) {
    x = levels > 0 ? std::floor(rng.Uniform(0.0, levels)) * 0.25 : std::abs(rng.Normal());
    if (infinite && rng.Uniform() < 0.1) x = kInf;
  }
  return a;
}

}  // namespace

TEST_CASE("SelectRank finds std::nth_element's value for every rank and guess",
          "[filter][doppler_fit]") {
  std::uint32_t draw = 0;
  for (int n = 1; n <= kFitMaxNeighbours; ++n) {
    for (const int levels : {0, 3, 12}) {
      for (const bool infinite : {false, true}) {
        CounterRng rng(7, RngPurpose::kTest, static_cast<std::uint64_t>(n), draw++);
        const std::vector<double> a = Values(rng, n, levels, infinite);
        const std::vector<double> before = a;
        for (int k = 0; k < n; ++k) {
          const double want = NthElement(a, k);
          // Guesses: every value itself, between values, beyond both ends.
          for (const double guess : {a[rng.NextU32() % n], want, 0.5 * want, want + 0.125, -1.0,
                                     0.0, 1e9, kInf, -kInf}) {
            INFO("n " << n << " k " << k << " levels " << levels << " guess " << guess);
            REQUIRE(Bits(filter::detail::SelectRank(a.data(), n, k, guess)) == Bits(want));
          }
        }
        REQUIRE(a == before);  // a untouched
      }
    }
  }
}

TEST_CASE("MadFloorBound is the largest median whose scale stays at the floor",
          "[filter][doppler_fit]") {
  for (const double floor : {0.0, 0.1, 0.05, 1.0, 0.3, 1e-300, 7.77e12}) {
    const double m = filter::detail::MadFloorBound(floor);
    INFO("floor " << floor << " bound " << m);
    CHECK(m >= 0.0);
    CHECK(1.4826 * m <= floor);
    CHECK(1.4826 * std::nextafter(m, kInf) > floor);
  }
}

TEST_CASE("RobustDopplerFit gives the plain fit's result bit for bit", "[filter][doppler_fit]") {
  // Lines of sight spread over `spread` rad around a random direction, radial speeds of one
  // velocity with Gaussian noise `sigma` around the floor 0.1 m/s, and a share of outliers
  // (another object's speeds): the floor binds in some passes and not in others, the median moves
  // by few or many ranks, some fits fail (too few inliers, parallel lines of sight).
  int fits = 0, failures = 0;
  std::uint32_t draw = 0;
  for (int n = 3; n <= kFitMaxNeighbours; ++n) {
    for (const double sigma : {0.0, 0.02, 0.07, 0.1, 0.2, 1.0}) {
      for (const double outliers : {0.0, 0.2, 0.45}) {
        for (const double spread : {0.0, 0.05, 1.5}) {
          CounterRng rng(11, RngPurpose::kTest, static_cast<std::uint64_t>(n), draw++);
          const double vx = rng.Uniform(-30.0, 30.0), vy = rng.Uniform(-5.0, 5.0);
          const double dir = rng.Uniform(-kPi, kPi);
          double ux[kFitMaxNeighbours], uy[kFitMaxNeighbours], y[kFitMaxNeighbours];
          for (int i = 0; i < n; ++i) {
            const double a = dir + rng.Uniform(-spread, spread);
            ux[i] = std::cos(a);
            uy[i] = std::sin(a);
            const bool out = rng.Uniform() < outliers;
            y[i] = (out ? 0.0 : ux[i] * vx + uy[i] * vy) + sigma * rng.Normal();
          }
          for (const double floor : {0.1, 0.5}) {
            const double bound = filter::detail::MadFloorBound(floor);
            DopplerFit got, want;
            const bool ok = filter::detail::RobustDopplerFit(ux, uy, y, n, floor, bound, &got);
            const bool ref = filter_ref::RobustFit(ux, uy, y, n, floor, &want);
            INFO("n " << n << " sigma " << sigma << " outliers " << outliers << " spread " << spread
                      << " floor " << floor);
            REQUIRE(ok == ref);
            ++fits;
            failures += !ok;
            if (!ok) continue;
            REQUIRE(Bits(got.vx) == Bits(want.vx));
            REQUIRE(Bits(got.vy) == Bits(want.vy));
            REQUIRE(Bits(got.scale) == Bits(want.scale));
            REQUIRE(Bits(got.a00) == Bits(want.a00));
            REQUIRE(Bits(got.a01) == Bits(want.a01));
            REQUIRE(Bits(got.a11) == Bits(want.a11));
            REQUIRE(got.inliers == want.inliers);
          }
        }
      }
    }
  }
  // Both outcomes were exercised.
  CHECK(failures > 0);
  CHECK(fits - failures > fits / 2);
}

TEST_CASE("RobustDopplerFit with non-finite inputs fails or matches the plain fit",
          "[filter][doppler_fit]") {
  // Huge radial speeds overflow the sums (inf, NaN residuals); NaN lines of sight fail the solve.
  const int n = 9;
  double ux[n], uy[n], y[n];
  for (int i = 0; i < n; ++i) {
    ux[i] = std::cos(0.3 * i);
    uy[i] = std::sin(0.3 * i);
    y[i] = i % 3 == 0 ? 1e308 : 0.1 * i;
  }
  for (const int poison : {-1, 4}) {
    if (poison >= 0) ux[poison] = std::numeric_limits<double>::quiet_NaN();
    DopplerFit got, want;
    const bool ok = filter::detail::RobustDopplerFit(ux, uy, y, n, 0.1,
                                                     filter::detail::MadFloorBound(0.1), &got);
    const bool ref = filter_ref::RobustFit(ux, uy, y, n, 0.1, &want);
    REQUIRE(ok == ref);
    if (ok) {
      CHECK(Bits(got.vx) == Bits(want.vx));
      CHECK(Bits(got.vy) == Bits(want.vy));
      CHECK(Bits(got.scale) == Bits(want.scale));
    }
  }
}

TEST_CASE("FitMemo finds a fit only under its exact key, the newest slots kept",
          "[filter][doppler_fit]") {
  using filter::detail::FitMemo;
  auto memo = std::make_unique<FitMemo>();
  const auto fit_of = [](int tag) {  // distinct outcomes per tag
    DopplerFit f;
    f.vx = 0.5 * tag;
    f.vy = -1.0 - tag;
    f.scale = 0.1 + tag;
    f.a00 = 2.0 * tag;
    f.a01 = 3.0 * tag;
    f.a11 = 4.0 * tag;
    f.inliers = tag;
    return f;
  };
  const auto key_of = [](int tag, int n) {  // keys of one tag share all but the last entry
    std::vector<int> key(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) key[static_cast<std::size_t>(i)] = 7 * i + (i == n - 1 ? tag : 0);
    return key;
  };
  bool ok = false;
  DopplerFit got;
  const std::vector<int> a = key_of(1000, kFitMaxNeighbours);
  CHECK_FALSE(memo->Find(a.data(), kFitMaxNeighbours, &ok, &got));  // empty
  memo->Add(a.data(), kFitMaxNeighbours, true, fit_of(1000));
  REQUIRE(memo->Find(a.data(), kFitMaxNeighbours, &ok, &got));
  CHECK(ok);
  CHECK(Bits(got.vx) == Bits(fit_of(1000).vx));
  CHECK(Bits(got.a11) == Bits(fit_of(1000).a11));
  CHECK(got.inliers == 1000);
  CHECK_FALSE(memo->Find(a.data(), kFitMaxNeighbours - 1, &ok, &got));  // a prefix
  const std::vector<int> other = key_of(1001, kFitMaxNeighbours);       // the last entry differs
  CHECK_FALSE(memo->Find(other.data(), kFitMaxNeighbours, &ok, &got));
  // Failed fits are remembered as failed; keys of 3 to kSlots + 2 entries, each found with its
  // outcome.
  for (int tag = 0; tag < FitMemo::kSlots; ++tag) {
    const std::vector<int> key = key_of(tag, 3 + tag);
    memo->Add(key.data(), 3 + tag, tag % 2 == 0, fit_of(tag));
  }
  for (int tag = 0; tag < FitMemo::kSlots; ++tag) {
    const std::vector<int> key = key_of(tag, 3 + tag);
    INFO("tag " << tag);
    REQUIRE(memo->Find(key.data(), 3 + tag, &ok, &got));
    CHECK(ok == (tag % 2 == 0));
    CHECK(got.inliers == tag);
    CHECK(Bits(got.scale) == Bits(fit_of(tag).scale));
  }
  // kSlots later fits took every slot: the first one is gone.
  CHECK_FALSE(memo->Find(a.data(), kFitMaxNeighbours, &ok, &got));
}

TEST_CASE("FastAtan2 on SIMD lanes gives the scalar bearing bit for bit", "[filter][fov]") {
  // The field of view's batched exact test (measurement_grid.cpp) takes its bearings from the
  // lanes: every octant, the axes, the origin, both zeros, octant boundaries and odd tails.
  std::vector<double> y, x;
  for (const double a : {0.0, -0.0, 1.0, -1.0, 1e-300, 5.0, -5.0}) {
    for (const double b : {0.0, -0.0, 1.0, -1.0, 1e-300, 5.0, -5.0}) {
      y.push_back(a);
      x.push_back(b);
    }
  }
  const std::size_t special = y.size();  // signed zeros: FastAtan2's own convention
  CounterRng rng(5, RngPurpose::kTest, 0, 0);
  for (int i = 0; i < 4001; ++i) {
    const double angle = rng.Uniform(-kPi, kPi), range = rng.Uniform(0.0, 300.0);
    y.push_back(range * std::sin(angle));
    x.push_back(range * std::cos(angle));
  }
  for (const int n : {static_cast<int>(y.size()), 1, 3, 0}) {
    std::vector<double> out(y.size(), -7.0);
    filter::detail::FastAtan2Lanes(y.data(), x.data(), n, out.data());
    for (int i = 0; i < n; ++i) {
      INFO("y " << y[i] << " x " << x[i]);
      REQUIRE(Bits(out[i]) == Bits(filter::detail::FastAtan2(y[i], x[i])));
      if (static_cast<std::size_t>(i) >= special)
        REQUIRE(std::abs(out[i] - std::atan2(y[i], x[i])) < 2.1e-4);
    }
  }
}
