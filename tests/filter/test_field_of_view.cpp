// The measurement grid's field-of-view and ray free-space bits (MeasurementGrid::view) against
// their per-cell definition: whatever segmentation FieldOfViewRow uses to skip per-cell bearings,
// every cell gets the bits of the plain test, bit for bit.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "dualgrid/core/random.hpp"
#include "dualgrid/filter/fast_atan2.hpp"
#include "dualgrid/filter/measurement_grid.hpp"

using namespace dualgrid;
using namespace dualgrid::filter;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

std::int64_t Mod(std::int64_t a, std::int64_t b) { return ((a % b) + b) % b; }

// Per sensor, per bearing bin, the range of the closest detection shadowing it (the bin of each
// detection of that sensor and free_bin_dilation bins each side).
std::vector<std::vector<double>> BinRanges(const FilterParams& fp,
                                           const std::vector<Measurement>& z,
                                           const std::vector<SensorCoverage>& cov) {
  std::vector<std::vector<double>> bins;
  for (const SensorCoverage& c : cov) {
    const int n = std::max(1, static_cast<int>(std::ceil(2.0 * c.half_fov / fp.free_angle_bin)));
    std::vector<double> b(n, kInf);
    for (const Measurement& m : z) {
      if ((c.origin - m.sensor_position).squaredNorm() > 1e-6) continue;
      const Vector2 d = m.position - c.origin;
      const double rel = WrapAngle(detail::FastAtan2(d.y(), d.x()) - c.boresight);
      if (std::abs(rel) > c.half_fov || d.norm() > c.max_range) continue;
      const int k = std::clamp(static_cast<int>((rel + c.half_fov) / fp.free_angle_bin), 0, n - 1);
      for (int q = std::max(0, k - fp.free_bin_dilation);
           q <= std::min(n - 1, k + fp.free_bin_dilation); ++q)
        b[q] = std::min(b[q], d.norm());
    }
    bins.push_back(std::move(b));
  }
  return bins;
}

// The bits of logical cell (lx, ly): per sensor the plain test (range, wedge, FastAtan2 bearing
// within the field of view, then its bin's range).
std::uint8_t PlainBits(const FilterParams& fp, const std::array<std::int64_t, 2>& origin, int lx,
                       int ly, const std::vector<SensorCoverage>& cov,
                       const std::vector<std::vector<double>>& bins) {
  const double r = fp.resolution;
  const double x0 = static_cast<double>(origin[0]) * r, y0 = static_cast<double>(origin[1]) * r;
  std::uint8_t bits = 0;
  for (std::size_t k = 0; k < cov.size(); ++k) {
    const SensorCoverage& c = cov[k];
    const double dy = y0 + (ly + 0.5) * r - c.origin.y();
    const double dx = x0 + (lx + 0.5) * r - c.origin.x();
    const double d2 = dx * dx + dy * dy;
    if (d2 < c.min_range * c.min_range || d2 > c.max_range * c.max_range) continue;
    const double cb = std::cos(c.boresight), sb = std::sin(c.boresight);
    const double fx = dx * cb + dy * sb, fy = dy * cb - dx * sb;
    if (c.half_fov < 0.5 * M_PI && (fx <= 0.0 || std::abs(fy) > fx * std::tan(c.half_fov)))
      continue;
    const double rel = detail::FastAtan2(fy, fx);
    if (std::abs(rel) > c.half_fov) continue;
    const int n = static_cast<int>(bins[k].size());
    const int b =
        std::clamp(static_cast<int>((rel + c.half_fov) * (1.0 / fp.free_angle_bin)), 0, n - 1);
    const double br = bins[k][b];
    bits |= 1 | (br == kInf ? 4 : 0) | (br != kInf && d2 < br * br ? 2 : 0);
  }
  return bits;
}

// Cells of the grid built for `centre` whose bits differ from the plain test's; counts (when
// given) adds the cells with bit 1, 2 and 4 and all cells.
int WrongCells(const FilterParams& fp, const Position& centre, const std::vector<Measurement>& z,
               const std::vector<SensorCoverage>& cov,
               std::array<std::int64_t, 4>* counts = nullptr) {
  MeasurementGrid mg(fp);
  mg.Build(centre, z, cov);
  const auto bins = BinRanges(fp, z, cov);
  const auto origin = mg.origin_index();
  const int nx = fp.CellsX(), ny = fp.CellsY();
  int wrong = 0;
  for (int ly = 0; ly < ny; ++ly) {
    for (int lx = 0; lx < nx; ++lx) {
      const std::uint8_t want = PlainBits(fp, origin, lx, ly, cov, bins);
      const std::int64_t s = Mod(origin[1] + ly, ny) * nx + Mod(origin[0] + lx, nx);
      wrong += mg.view()[s] != want;
      if (counts != nullptr) {
        for (int b = 0; b < 3; ++b) (*counts)[b] += (want & (1 << b)) != 0;
        ++(*counts)[3];
      }
    }
  }
  return wrong;
}

}  // namespace

// The row walk's corner cases: sensors on a row of cell centres or within 1e-7 m of one (the
// rows through them take the bisection), boresights along the axes and diagonals (bounds parallel
// to the rows, FastAtan2's octant jump), half angles near pi/2 and near 0, a minimum range that
// rows cross, far origins, few detections and many, wide runs of one range (wide bins or
// dilation: arcs that turn through +-y, across many rows).
TEST_CASE("the field of view's row walk keeps the per-cell bits in corner cases", "[filter][fov]") {
  FilterParams fp;
  fp.length_x = 60.0;  // 120 x 50 cells: more scenes
  CounterRng rng(3737, RngPurpose::kTest, 0, 0);
  for (int scene = 0; scene < 150; ++scene) {
    // Wide runs of one range (wide bins, wide dilation): arcs that turn through +-y.
    fp.free_angle_bin = scene % 5 == 2 ? 0.1 : 1.0 * M_PI / 180.0;
    fp.free_bin_dilation = scene % 5 == 3 ? 15 : 1;
    const double far = scene % 3 == 0 ? 1e6 : 0.0;
    const Position ego(far + rng.Uniform(-100.0, 100.0), -far + rng.Uniform(-100.0, 100.0));
    std::vector<SensorCoverage> cov;
    for (int k = 0; k < 4; ++k) {
      Position o = ego + Vector2(rng.Uniform(-4.0, 4.0), rng.Uniform(-4.0, 4.0));
      if ((scene + k) % 4 == 0) o.y() = (std::floor(o.y() / 0.5) + 0.5) * 0.5;  // on a row
      if ((scene + k) % 4 == 1) o.y() = (std::floor(o.y() / 0.5) + 0.5) * 0.5 + 1e-7;
      double boresight = rng.Uniform(-M_PI, M_PI);
      if ((scene + k) % 3 == 0) boresight = M_PI / 4.0 * std::floor(rng.Uniform(-4.0, 4.0));
      const double u = rng.Uniform(0.0, 1.0);
      const double hf = u < 0.2   ? M_PI / 2.0 - rng.Uniform(1e-9, 1e-3)
                        : u < 0.3 ? rng.Uniform(1e-4, 0.05)
                                  : rng.Uniform(0.1, 1.5);
      const double min_range = scene % 2 == 0 ? rng.Uniform(0.0, 6.0) : 0.0;
      cov.push_back({o, boresight, hf, min_range, rng.Uniform(10.0, 70.0)});
    }
    std::vector<Measurement> z;
    const int nz = scene % 4 == 0 ? 3 : static_cast<int>(rng.Uniform(0.0, 400.0));
    for (int j = 0; j < nz; ++j) {
      const SensorCoverage& c = cov[static_cast<std::size_t>(j) % cov.size()];
      const double a = c.boresight + rng.Uniform(-c.half_fov, c.half_fov);
      const double range = rng.Uniform(0.3, 1.1 * c.max_range);
      z.push_back(
          {c.origin + range * Vector2(std::cos(a), std::sin(a)), Velocity(0.0, 0.0), c.origin});
    }
    const Position centre = ego + Vector2(rng.Uniform(-2.0, 2.0), rng.Uniform(-2.0, 2.0));
    INFO("scene " << scene << " with " << nz << " detections");
    CHECK(WrongCells(fp, centre, z, cov) == 0);
  }
}

TEST_CASE("every cell's field-of-view bits are those of the plain per-cell test", "[filter][fov]") {
  FilterParams fp;  // 200 m x 25 m at 0.5 m, 1 deg bins
  CounterRng rng(37, RngPurpose::kTest, 0, 0);
  std::array<std::int64_t, 4> counts{};  // cells with bit 1, 2, 4; all cells
  for (int scene = 0; scene < 40; ++scene) {
    // Five radars around an ego (narrow corner and side ones, a front one, sometimes a wide or
    // full-circle one), detections along their rays (some far beyond the grid).
    const Position ego(rng.Uniform(-1e4, 1e4), rng.Uniform(-1e3, 1e3));
    std::vector<SensorCoverage> cov;
    for (int k = 0; k < 5; ++k) {
      const double hf = scene % 7 == 3 && k == 0   ? M_PI
                        : scene % 5 == 1 && k == 1 ? rng.Uniform(1.6, 3.0)
                                                   : rng.Uniform(0.2, 1.4);
      cov.push_back({ego + Vector2(rng.Uniform(-3.0, 3.0), rng.Uniform(-1.0, 1.0)),
                     rng.Uniform(-M_PI, M_PI), hf, rng.Uniform(0.0, 1.0), rng.Uniform(20.0, 90.0)});
    }
    std::vector<Measurement> z;
    const int nz = static_cast<int>(rng.Uniform(0.0, 600.0));
    for (int j = 0; j < nz; ++j) {
      const SensorCoverage& c = cov[static_cast<std::size_t>(j) % cov.size()];
      const double a = c.boresight + rng.Uniform(-c.half_fov, c.half_fov);
      const double range = rng.Uniform(0.5, 1.1 * c.max_range);
      const Position p = c.origin + range * Vector2(std::cos(a), std::sin(a));
      z.push_back({p, Velocity(0.0, 0.0), c.origin});
    }
    const Position centre = ego + Vector2(rng.Uniform(-2.0, 2.0), rng.Uniform(-2.0, 2.0));
    INFO("scene " << scene << " with " << nz << " detections");
    CHECK(WrongCells(fp, centre, z, cov, &counts) == 0);
  }
  // The scenes reach every kind of cell.
  const auto [observed, free_ray, no_return, cells] = counts;
  CHECK(observed > cells / 4);
  CHECK(free_ray > cells / 50);
  CHECK(no_return > cells / 50);
}
