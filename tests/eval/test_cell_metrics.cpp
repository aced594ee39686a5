#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <catch2/catch.hpp>

#include "dualgrid/core/random.hpp"
#include "dualgrid/eval/cell_metrics.hpp"

using dualgrid::OrientedBox;
using dualgrid::Position;
using dualgrid::eval::CellClass;
using dualgrid::eval::CellClassificationAccumulator;
using dualgrid::eval::CellMetrics;
using dualgrid::eval::ClassifyCell;
using dualgrid::eval::RasterizeTruth;

namespace {
constexpr std::uint8_t F = 0, S = 1, D = 2, U = 3;
}

TEST_CASE("ClassifyCell uses the 0.6 threshold strictly", "[cells]") {
  CHECK(ClassifyCell(0.1, 0.2, 0.61) == CellClass::kDynamic);
  CHECK(ClassifyCell(0.2, 0.2, 0.6) == CellClass::kUnknown);  // "larger than 0.6"
  CHECK(ClassifyCell(0.1, 0.7, 0.2) == CellClass::kStatic);
  CHECK(ClassifyCell(0.9, 0.05, 0.05) == CellClass::kFree);
  CHECK(ClassifyCell(0.4, 0.3, 0.3) == CellClass::kUnknown);
}

TEST_CASE("Confusion matrix and scores counted by hand", "[cells]") {
  // truth:     D D D D S S F F F F
  // predicted: D D D F D S F F U D
  // observed:  all but the last cell in frame 1; frame 2 repeats the first 4 cells.
  const std::vector<std::uint8_t> truth = {D, D, D, D, S, S, F, F, F, F};
  const std::vector<std::uint8_t> pred = {D, D, D, F, D, S, F, F, U, D};
  std::vector<std::uint8_t> observed(10, 1);
  observed[9] = 0;
  CellClassificationAccumulator acc;
  acc.AddFrame(pred, truth, observed);
  acc.AddFrame(std::span(pred).first(4), std::span(truth).first(4));
  const CellMetrics m = acc.Result();
  CHECK(m.frames == 2);
  CHECK(m.cells == 13);
  // Dynamic truth row: 3 + 3 predicted dynamic, 1 + 1 predicted free.
  CHECK(m.confusion[D][D] == 6);
  CHECK(m.confusion[D][F] == 2);
  CHECK(m.confusion[S][D] == 1);
  CHECK(m.confusion[S][S] == 1);
  CHECK(m.confusion[F][F] == 2);
  CHECK(m.confusion[F][U] == 1);
  CHECK(m.confusion[F][D] == 0);  // the unobserved cell is not counted
  // Dynamic: TP 6, FP 1, FN 2.
  CHECK(*m.dynamic_precision == Approx(6.0 / 7.0));
  CHECK(*m.dynamic_recall == Approx(6.0 / 8.0));
  CHECK(*m.dynamic_f1 == Approx(12.0 / 15.0));
  // Static: TP 1, FP 0, FN 1.
  CHECK(*m.static_precision == Approx(1.0));
  CHECK(*m.static_recall == Approx(0.5));
  CHECK(*m.accuracy == Approx((6.0 + 1.0 + 2.0) / 13.0));
}

TEST_CASE("ClassifyCells equals ClassifyCell cell by cell", "[cells][property]") {
  // Masses from a small set that includes the thresholds themselves, float neighbours of them,
  // 0, 1 and NaN, in every combination, for two thresholds (0.6 and 0.5, where two classes tie).
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (const double threshold : {0.6, 0.5}) {
    const float t = static_cast<float>(threshold);
    const std::vector<float> values = {
        0.0f, 0.2f, std::nextafter(t, 0.0f), t, std::nextafter(t, 1.0f), 0.61f, 1.0f, nan};
    std::vector<float> fr, st, dy;
    for (float a : values)
      for (float b : values)
        for (float c : values) {
          fr.push_back(a);
          st.push_back(b);
          dy.push_back(c);
        }
    std::vector<std::uint8_t> out(fr.size(), 255);
    dualgrid::eval::ClassifyCells(fr, st, dy, threshold, out);
    int differ = 0;
    for (std::size_t i = 0; i < out.size(); ++i)
      differ += out[i] != static_cast<std::uint8_t>(ClassifyCell(fr[i], st[i], dy[i], threshold));
    INFO("threshold " << threshold);
    CHECK(differ == 0);
  }
  std::vector<std::uint8_t> short_out(3);
  const std::vector<float> four(4, 0.0f);
  CHECK_THROWS_AS(dualgrid::eval::ClassifyCells(four, four, four, 0.6, short_out),
                  std::invalid_argument);
}

TEST_CASE("The confusion matrix equals a plain count over random frames", "[cells][property]") {
  const std::uint64_t seed = GENERATE(range(1, 6));
  dualgrid::CounterRng rng(seed, dualgrid::RngPurpose::kTest, 0, 0);
  CellClassificationAccumulator acc;
  std::array<std::array<std::int64_t, 4>, 3> expected{};
  std::int64_t cells = 0;
  for (int frame = 0; frame < 4; ++frame) {
    // The last frame spans several of AddFrame's chunks (4,096 cells) and byte counters (255).
    const std::size_t n = 1 + static_cast<std::size_t>(rng.Uniform() * (frame == 3 ? 12997 : 997));
    std::vector<std::uint8_t> truth(n), pred(n), observed(n);
    for (std::size_t i = 0; i < n; ++i) {
      truth[i] = static_cast<std::uint8_t>(rng.Uniform() * 3);
      pred[i] = static_cast<std::uint8_t>(rng.Uniform() * 4);
      observed[i] = static_cast<std::uint8_t>(rng.Uniform() < 0.7 ? 1 + rng.Uniform() * 3 : 0);
      if (observed[i] != 0) {
        ++expected[truth[i]][pred[i]];
        ++cells;
      }
    }
    acc.AddFrame(pred, truth, observed);
  }
  // One class in every cell of a long frame: every byte counter full (255 of 255).
  const std::vector<std::uint8_t> same(5000, 1);
  acc.AddFrame(same, same, {});
  expected[1][1] += 5000;
  cells += 5000;
  const CellMetrics m = acc.Result();
  CHECK(m.confusion == expected);
  CHECK(m.cells == cells);
  // A class out of range in an unobserved cell is ignored; in an observed one the frame is
  // refused and none of its cells counted.
  std::vector<std::uint8_t> truth(9, 0), pred(9, 0), observed(9, 1);
  truth[4] = 3;
  observed[4] = 0;
  acc.AddFrame(pred, truth, observed);
  CHECK(acc.Result().cells == cells + 8);
  observed[4] = 1;
  CHECK_THROWS_AS(acc.AddFrame(pred, truth, observed), std::invalid_argument);
  CHECK(acc.Result().cells == cells + 8);
  // The same among cells counted 16 at a time: a predicted class 4 with truth 0 would read as
  // truth 1, predicted 0 if it were counted.
  std::vector<std::uint8_t> truth2(100, 0), pred2(100, 0), observed2(100, 0);
  pred2[40] = 4;
  acc.AddFrame(pred2, truth2, observed2);
  CHECK(acc.Result().cells == cells + 8);
  observed2[40] = 1;
  observed2[99] = 1;
  CHECK_THROWS_WITH(acc.AddFrame(pred2, truth2, observed2), Catch::Contains("cell 40 "));
  CHECK(acc.Result().cells == cells + 8);
  expected[0][0] += 8;
  CHECK(acc.Result().confusion == expected);
}

TEST_CASE("Cell scores are empty without the class", "[cells]") {
  const std::vector<std::uint8_t> truth = {F, F}, pred = {F, U};
  CellClassificationAccumulator acc;
  acc.AddFrame(pred, truth);
  const CellMetrics m = acc.Result();
  CHECK_FALSE(m.dynamic_precision);
  CHECK_FALSE(m.dynamic_recall);
  CHECK_FALSE(m.dynamic_f1);
  CHECK(*m.accuracy == Approx(0.5));
  CHECK_THROWS_AS(acc.AddFrame(pred, std::vector<std::uint8_t>{F}), std::invalid_argument);
  CHECK_THROWS_AS(acc.AddFrame(std::vector<std::uint8_t>{4}, std::vector<std::uint8_t>{F}),
                  std::invalid_argument);
}

TEST_CASE("RasterizeTruth marks cell centres inside boxes, moving over stationary", "[cells]") {
  // 0.5 m cells, centres at (0.25 + 0.5 i, 0.25 + 0.5 j) for a 20 x 8 grid.
  std::vector<Position> centers;
  for (int j = 0; j < 8; ++j)
    for (int i = 0; i < 20; ++i) centers.emplace_back(0.25 + 0.5 * i, 0.25 + 0.5 * j);
  const double yaw = GENERATE(0.0, 0.4, -1.2);
  const std::vector<OrientedBox> moving = {{{3.0, 2.0}, yaw, 4.5, 1.8}};
  const std::vector<OrientedBox> stationary = {{{3.0, 2.0}, 0.0, 9.0, 0.6},
                                               {{8.0, 3.0}, 0.0, 2.0, 1.0}};
  std::vector<std::uint8_t> out(centers.size(), 99);
  RasterizeTruth(centers, moving, stationary, out);
  for (std::size_t i = 0; i < centers.size(); ++i) {
    const auto expected = moving[0].Contains(centers[i])       ? D
                          : stationary[0].Contains(centers[i]) ? S
                          : stationary[1].Contains(centers[i]) ? S
                                                               : F;
    CHECK(out[i] == expected);
  }
  // The car covers about 4.5 * 1.8 / 0.25 = 32 cell centres; allow the rasterisation slack of
  // one perimeter row (perimeter 12.6 m / 0.5 m ~ 25 cells).
  int dynamic = 0;
  for (const auto c : out) dynamic += c == D;
  CHECK(dynamic >= 32 - 25);
  CHECK(dynamic <= 32 + 25);
  CHECK_THROWS_AS(RasterizeTruth(centers, moving, stationary, std::span(out).first(3)),
                  std::invalid_argument);
}

TEST_CASE("RasterizeTruth on a regular grid equals the per-centre overload", "[cells]") {
  // Sampled boxes (any yaw, partly outside, on exact cell boundaries, axis-aligned one-cell-wide
  // rails whose edges pass through centres) on a grid whose origin index is negative.
  const dualgrid::eval::RegularGrid grid{-37, 12, 0.5, 60, 24};
  std::vector<Position> centers;
  for (int y = 0; y < grid.cells_y; ++y)
    for (int x = 0; x < grid.cells_x; ++x)
      centers.emplace_back((static_cast<double>(grid.origin_ix + x) + 0.5) * grid.resolution,
                           (static_cast<double>(grid.origin_iy + y) + 0.5) * grid.resolution);
  dualgrid::CounterRng rng(7, dualgrid::RngPurpose::kTest, 0, 0);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<OrientedBox> moving, stationary;
    for (int k = 0; k < 4; ++k) {
      OrientedBox b{{-22.0 + 30.0 * rng.Uniform(), 3.0 + 15.0 * rng.Uniform()},
                    -4.0 + 8.0 * rng.Uniform(),
                    0.2 + 15.0 * rng.Uniform(),
                    0.2 + 3.0 * rng.Uniform()};
      (k % 2 == 0 ? moving : stationary).push_back(b);
    }
    // A rail one cell wide centred on a row of cell edges: its long sides pass through centres.
    stationary.push_back({{-5.0, 9.0}, 0.0, 40.0, grid.resolution});
    std::vector<std::uint8_t> a(centers.size(), 99), b(centers.size(), 99);
    RasterizeTruth(centers, moving, stationary, a);
    RasterizeTruth(grid, moving, stationary, b);
    REQUIRE(a == b);
  }
  std::vector<std::uint8_t> wrong(3);
  CHECK_THROWS_AS(RasterizeTruth(grid, {}, {}, wrong), std::invalid_argument);
}
