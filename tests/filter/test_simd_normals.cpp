// The Philox draws and prediction normals on SIMD lanes (simd_normals.hpp) against the scalar
// definitions: CounterRng's raw draws and the scalar Box-Muller path, bit for bit.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <vector>

#include "dualgrid/core/random.hpp"
#include "dualgrid/filter/prediction_noise.hpp"
#include "dualgrid/filter/simd_normals.hpp"
#include "reference/fast_normal.hpp"

using namespace dualgrid;
using namespace dualgrid::filter;

TEST_CASE("Philox on lanes draws CounterRng's values bit for bit", "[filter][simd][noise]") {
  const std::uint64_t seed = GENERATE(1ull, 0x123456789abcdefull);
  const std::uint64_t step = GENERATE(0ull, 7ull, (1ull << 40) + 3);
  const std::uint32_t first = GENERATE(0u, 13u, 0xFFFFFFF0u);  // the last wraps the index
  const std::int64_t n = 37;                                   // a tail of one lane
  std::vector<std::uint32_t> out[8];
  for (auto& o : out) o.assign(n + 1, 0xDEADBEEFu);
  detail::PhiloxLanes(seed, static_cast<std::uint32_t>(RngPurpose::kFilterBirth), step, first, n, 0,
                      out[0].data(), out[1].data(), out[2].data(), out[3].data());
  detail::PhiloxLanes(seed, static_cast<std::uint32_t>(RngPurpose::kFilterBirth), step, first, n, 1,
                      out[4].data(), out[5].data(), out[6].data(), out[7].data());
  for (std::int64_t k = 0; k < n; ++k) {
    CounterRng rng(seed, RngPurpose::kFilterBirth, step, first + static_cast<std::uint32_t>(k));
    for (int c = 0; c < 8; ++c) REQUIRE(out[c][k] == rng.NextU32());  // blocks 0 and 1
  }
  for (const auto& o : out) CHECK(o[n] == 0xDEADBEEFu);  // nothing written past n
}

TEST_CASE("prediction normals on lanes are the scalar path's, bit for bit",
          "[filter][simd][noise]") {
  // The scalar definition: the double reference's (27d8ca3) PhiloxBlocks and BoxMuller, which
  // the filter used before the lanes; and PredictionNoise, which now draws through the lanes.
  const std::uint64_t seed = GENERATE(3ull, 99ull);
  const std::uint64_t step = GENERATE(0ull, 12ull);
  const std::int64_t n = 203;  // a tail of three lanes
  std::vector<std::uint32_t> raw[4];
  std::vector<float> u[4], want[4], got[4];
  for (int c = 0; c < 4; ++c) {
    raw[c].resize(n);
    u[c].resize(n);
    want[c].resize(n);
    got[c].assign(n, NAN);
  }
  const std::uint32_t first = 517;
  filter_ref::detail::PhiloxBlocks(seed, RngPurpose::kFilterPredict, step, first, n, 0,
                                   raw[0].data(), raw[1].data(), raw[2].data(), raw[3].data());
  for (int c = 0; c < 4; ++c)
    for (std::int64_t k = 0; k < n; ++k) u[c][k] = filter_ref::detail::ToUnit24(raw[c][k]);
  filter_ref::detail::BoxMuller(u[0].data(), u[1].data(), want[0].data(), want[1].data(), n);
  filter_ref::detail::BoxMuller(u[2].data(), u[3].data(), want[2].data(), want[3].data(), n);
  detail::PredictionNormalLanes(seed, step, first, n, got[0].data(), got[1].data(), got[2].data(),
                                got[3].data());
  PredictionNoise noise;
  noise.Draw(seed, step, first + n);
  for (int c = 0; c < 4; ++c) {
    for (std::int64_t k = 0; k < n; ++k) {
      REQUIRE(got[c][k] == want[c][k]);
      REQUIRE(noise.channel(c)[first + k] == want[c][k]);
    }
  }
}

TEST_CASE("births' uniforms and normals on lanes are the scalar ToUnit24 and Normal2FromRaw",
          "[filter][simd][noise]") {
  // Raw words from CounterRng plus the extremes of the 24 bits used (0, all ones: the log's
  // argument 1 and 2^-24); n = 203 leaves a tail of three lanes.
  const std::int64_t n = 203;
  std::vector<std::uint32_t> r1(n), r2(n);
  CounterRng rng(11, RngPurpose::kTest, 4, 0);
  for (std::int64_t k = 0; k < n; ++k) {
    r1[k] = rng.NextU32();
    r2[k] = rng.NextU32();
  }
  r1[0] = 0u;
  r1[1] = 0xFFFFFFFFu;
  r2[2] = 0u;
  r2[3] = 0xFFFFFFFFu;
  std::vector<float> u(n + 1, NAN), a(n + 1, NAN), b(n + 1, NAN);
  detail::Unit24Lanes(r1.data(), n, u.data());
  detail::Normal2Lanes(r1.data(), r2.data(), n, a.data(), b.data());
  for (std::int64_t k = 0; k < n; ++k) {
    float wa, wb;
    filter_ref::detail::Normal2FromRaw(r1[k], r2[k], &wa, &wb);
    INFO("k " << k);
    REQUIRE(u[k] == filter_ref::detail::ToUnit24(r1[k]));
    REQUIRE(a[k] == wa);
    REQUIRE(b[k] == wb);
  }
  CHECK(std::isnan(u[n]));  // nothing written past n
  CHECK(std::isnan(a[n]));
  CHECK(std::isnan(b[n]));
  CHECK(a[1] == 0.0f);  // log(1) = 0: a zero radius
}

TEST_CASE("prediction normals on lanes are standard normal", "[filter][simd][noise]") {
  // 4 x 40,000 draws: the mean's standard error is 1/200 and the variance's sqrt(2/40000) = 0.007;
  // 5 standard errors each (the approximations' error, < 2e-5, is far below).
  const std::int64_t n = 40000;
  std::vector<float> g[4];
  for (auto& c : g) c.resize(n);
  detail::PredictionNormalLanes(5, 1, 0, n, g[0].data(), g[1].data(), g[2].data(), g[3].data());
  for (int c = 0; c < 4; ++c) {
    double s = 0, s2 = 0;
    for (const float v : g[c]) {
      s += v;
      s2 += static_cast<double>(v) * v;
    }
    const double mean = s / n, var = s2 / n - mean * mean;
    CHECK(std::abs(mean) < 5.0 / 200.0);
    CHECK(std::abs(var - 1.0) < 5.0 * std::sqrt(2.0 / n));
  }
}
