// The measurement grid's fast paths against their definitions, bit for bit: the Doppler fit's
// median (filter/src/doppler_fit.cpp: SelectRank against std::nth_element, MadFloorBound against
// its defining property, RobustDopplerFit against the plain fit of reference/doppler_fit.hpp on
// random neighbourhoods that take every path: the floor, a median near the last one, the
// quickselect, failures, NaN; RobustDopplerFitPair and RunFits against RobustDopplerFit; FitMemo's
// keys; GatherNeighbours against the bucket-by-bucket gathering) and the field of view's bearings
// on SIMD lanes (FastAtan2Lanes).
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

// A neighbourhood as RobustDopplerFit takes it: lines of sight spread over `spread` rad around a
// random direction, radial speeds of one velocity with Gaussian noise `sigma` and a share
// `outliers` of another object's (zero) speeds.
struct Hood {
  std::vector<double> ux, uy, y;
  int n() const { return static_cast<int>(ux.size()); }
};

Hood DrawHood(CounterRng& rng, int n, double sigma, double outliers, double spread) {
  const double vx = rng.Uniform(-30.0, 30.0), vy = rng.Uniform(-5.0, 5.0);
  const double dir = rng.Uniform(-kPi, kPi);
  Hood h;
  for (int i = 0; i < n; ++i) {
    const double a = dir + rng.Uniform(-spread, spread);
    h.ux.push_back(std::cos(a));
    h.uy.push_back(std::sin(a));
    const bool out = rng.Uniform() < outliers;
    h.y.push_back((out ? 0.0 : h.ux.back() * vx + h.uy.back() * vy) + sigma * rng.Normal());
  }
  return h;
}

// A random neighbourhood of every kind: n from 3 to kFitMaxNeighbours; noise at, below and above
// the floor; outliers; lines of sight parallel or spread; now and then a NaN or infinite entry or
// a radial speed that overflows the sums.
Hood AnyHood(CounterRng& rng) {
  const int n = 3 + static_cast<int>(rng.NextU32() % (kFitMaxNeighbours - 2));
  const double sigmas[] = {0.0, 0.02, 0.07, 0.1, 0.2, 1.0}, shares[] = {0.0, 0.2, 0.45},
               spreads[] = {0.0, 0.05, 1.5};
  Hood h = DrawHood(rng, n, sigmas[rng.NextU32() % 6], shares[rng.NextU32() % 3],
                    spreads[rng.NextU32() % 3]);
  const double u = rng.Uniform();
  const std::size_t at = rng.NextU32() % static_cast<std::uint32_t>(n);
  if (u < 0.03) h.ux[at] = std::numeric_limits<double>::quiet_NaN();
  if (u > 0.97) h.y[at] = rng.Uniform() < 0.5 ? kInf : 1e308;
  return h;
}

// RobustDopplerFit's outcome on h; true when f equals it bit for bit (when it succeeded).
bool SameAsSingle(const Hood& h, bool ok, const DopplerFit& f, double floor) {
  DopplerFit want;
  const bool ref =
      filter::detail::RobustDopplerFit(h.ux.data(), h.uy.data(), h.y.data(), h.n(), floor,
                                       filter::detail::MadFloorBound(floor), &want);
  if (ok != ref) return false;
  return !ok || (Bits(f.vx) == Bits(want.vx) && Bits(f.vy) == Bits(want.vy) &&
                 Bits(f.scale) == Bits(want.scale) && Bits(f.a00) == Bits(want.a00) &&
                 Bits(f.a01) == Bits(want.a01) && Bits(f.a11) == Bits(want.a11) &&
                 f.inliers == want.inliers);
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

TEST_CASE("RobustDopplerFitPair gives each lane's single fit bit for bit",
          "[filter][doppler_fit]") {
  // Pairs of neighbourhoods of every kind, of equal and of different sizes (the shorter one
  // padded), fits that fail (at the start or in a later reweighting) beside fits that do not.
  CounterRng rng(13, RngPurpose::kTest, 0, 0);
  int outcomes[2][2] = {};  // [lane 0 ok][lane 1 ok]
  double guess = 1.0;       // the pairs' first median guess
  for (int pair = 0; pair < 6000; ++pair) {
    const Hood a = AnyHood(rng);
    const Hood b = pair % 5 == 0 ? DrawHood(rng, a.n(), 0.1, 0.2, 1.5) : AnyHood(rng);
    const double floor = pair % 2 == 0 ? 0.1 : 0.5;
    const filter::detail::FitInput in[2] = {{a.ux.data(), a.uy.data(), a.y.data(), a.n()},
                                            {b.ux.data(), b.uy.data(), b.y.data(), b.n()}};
    DopplerFit f[2];
    bool ok[2];
    // Any first guess (it only steers the selection): the last pair's, or a far one.
    if (pair % 3 == 0) guess = pair % 2 == 0 ? kInf : 0.0;
    filter::detail::RobustDopplerFitPair(in, floor, filter::detail::MadFloorBound(floor), f, ok,
                                         &guess);
    INFO("pair " << pair << " n " << a.n() << ", " << b.n());
    REQUIRE(SameAsSingle(a, ok[0], f[0], floor));
    REQUIRE(SameAsSingle(b, ok[1], f[1], floor));
    ++outcomes[ok[0]][ok[1]];
  }
  // Every mix of outcomes was exercised.
  for (const int lane0 : {0, 1}) {
    for (const int lane1 : {0, 1}) CHECK(outcomes[lane0][lane1] > 50);
  }
}

TEST_CASE("RunFits gives every detection its single fit, repeats and short lists included",
          "[filter][doppler_fit]") {
  using filter::detail::RunFits;
  CounterRng rng(17, RngPurpose::kTest, 0, 0);
  for (int round = 0; round < 300; ++round) {
    // A run of distinct neighbourhoods, some of them repeated (right after, or later: while
    // queued or remembered), and some with fewer than 3 neighbours.
    const int size = 1 + static_cast<int>(rng.NextU32() % RunFits::kRun);
    std::vector<Hood> hoods;
    std::vector<std::vector<int>> keys;
    for (int i = 0; i < size; ++i) {
      const double u = rng.Uniform();
      if (i > 0 && u < 0.4) {  // a repeat of an earlier one (often the last)
        const std::size_t of = u < 0.25 ? hoods.size() - 1 : rng.NextU32() % hoods.size();
        hoods.push_back(hoods[of]);
        keys.push_back(keys[of]);
        continue;
      }
      hoods.push_back(u > 0.95 ? DrawHood(rng, static_cast<int>(rng.NextU32() % 3), 0.1, 0.0, 1.5)
                               : AnyHood(rng));
      std::vector<int> key(hoods.back().ux.size());
      for (std::size_t k = 0; k < key.size(); ++k) key[k] = 1000 * i + static_cast<int>(k);
      keys.push_back(key);
    }
    // The neighbours' (ux, uy, y) by key, as Submit reads them.
    std::vector<double> by_key(3 * 1000 * RunFits::kRun, std::nan(""));
    for (int i = 0; i < size; ++i) {
      const Hood& h = hoods[static_cast<std::size_t>(i)];
      for (int k = 0; k < h.n(); ++k) {
        const std::size_t e = 3 * static_cast<std::size_t>(keys[static_cast<std::size_t>(i)][k]);
        by_key[e] = h.ux[k];
        by_key[e + 1] = h.uy[k];
        by_key[e + 2] = h.y[k];
      }
    }
    auto fits = std::make_unique<RunFits>(0.1, filter::detail::MadFloorBound(0.1));
    for (int i = 0; i < size; ++i) {
      RunFits::Gathered& g = fits->Next();
      const Hood& h = hoods[static_cast<std::size_t>(i)];
      std::copy(keys[static_cast<std::size_t>(i)].begin(), keys[static_cast<std::size_t>(i)].end(),
                g.key);
      fits->Submit(i, h.n(), by_key.data());
    }
    fits->Finish();
    for (int i = 0; i < size; ++i) {
      const Hood& h = hoods[static_cast<std::size_t>(i)];
      DopplerFit f;
      const bool ok = fits->Result(i, &f);
      INFO("round " << round << " detection " << i << " n " << h.n());
      if (h.n() < 3) {
        REQUIRE_FALSE(ok);
      } else {
        REQUIRE(SameAsSingle(h, ok, f, 0.1));
      }
    }
  }
}

TEST_CASE("GatherNeighbours keeps the neighbours of the bucket-by-bucket gathering",
          "[filter][doppler_fit]") {
  CounterRng rng(23, RngPurpose::kTest, 0, 0);
  int capped = 0, budget = 0, gathered = 0;  // queries that hit each cap; with neighbours
  for (int round = 0; round < 400; ++round) {
    // A bucket grid of nbx x nby buckets of edge e from (ox, oy), points placed as BucketOf
    // places them (the edge buckets reaching out), some rounds crowded.
    const int nbx = 1 + static_cast<int>(rng.NextU32() % 9),
              nby = 1 + static_cast<int>(rng.NextU32() % 9);
    const double e = rng.Uniform(0.5, 4.0), inv = 1.0 / e;
    const double ox = rng.Uniform(-50.0, 50.0), oy = rng.Uniform(-50.0, 50.0);
    const int points = static_cast<int>(rng.NextU32() % (round % 4 == 0 ? 3000 : 200));
    const auto bucket_of = [&](double px, double py) {
      const double fx = std::clamp(std::floor((px - ox) * inv), 0.0, nbx - 1.0);
      const double fy = std::clamp(std::floor((py - oy) * inv), 0.0, nby - 1.0);
      return std::pair<int, int>{static_cast<int>(fx), static_cast<int>(fy)};
    };
    const auto draw = [&] {  // a point on or a little beyond the grid
      return std::pair<double, double>{ox + rng.Uniform(-0.2, 1.2) * nbx * e,
                                       oy + rng.Uniform(-0.2, 1.2) * nby * e};
    };
    std::vector<std::vector<std::pair<double, double>>> in(static_cast<std::size_t>(nbx * nby));
    for (int i = 0; i < points; ++i) {
      const auto p = draw();
      const auto [bx, by] = bucket_of(p.first, p.second);
      in[static_cast<std::size_t>(by * nbx + bx)].push_back(p);
    }
    std::vector<double> x, y;
    std::vector<std::int64_t> start{0};
    for (const auto& b : in) {
      for (const auto& p : b) {
        x.push_back(p.first);
        y.push_back(p.second);
      }
      start.push_back(static_cast<std::int64_t>(x.size()));
    }
    const filter::detail::BucketView v{x.data(), y.data(), start.data(), nbx, nby, inv, ox, oy};
    for (int q = 0; q < 20; ++q) {
      const auto [px, py] =
          q < 10 && !x.empty()
              ? std::pair<double, double>{x[rng.NextU32() % x.size()], y[rng.NextU32() % y.size()]}
              : draw();
      const auto [bx, by] = bucket_of(px, py);
      // Small radii in crowded rounds: the candidates' budget binds before the list is full.
      const bool small = round % 4 == 0 && q % 2 == 0;
      const double radius = (small ? rng.Uniform(0.05, 0.4) : rng.Uniform(0.1, 2.5)) * e;
      const int reach = static_cast<int>(std::ceil(radius * inv));
      int want[kFitMaxNeighbours], got[kFitMaxNeighbours];
      const int n_want = filter_ref::GatherRef(v, px, py, bx, by, reach, radius * radius, want);
      const int n_got =
          filter::detail::GatherNeighbours(v, px, py, bx, by, reach, radius * radius, got);
      INFO("round " << round << " query " << q);
      REQUIRE(n_got == n_want);
      REQUIRE(std::equal(want, want + n_want, got));
      capped += n_want == kFitMaxNeighbours;
      gathered += n_want > 0;
      int within = 0;  // all points within the radius: more than kept under the cap: the budget
      for (std::size_t k = 0; k < x.size(); ++k)
        within += !((x[k] - px) * (x[k] - px) + (y[k] - py) * (y[k] - py) > radius * radius);
      budget += n_want < std::min(within, kFitMaxNeighbours);
    }
  }
  // Every path taken: queries with and without neighbours, lists cut at kFitMaxNeighbours and
  // by the kMaxCandidates looked at.
  INFO("capped " << capped << " budget " << budget << " gathered " << gathered);
  CHECK(capped > 50);
  CHECK(budget > 50);
  CHECK(gathered > 1000);
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
