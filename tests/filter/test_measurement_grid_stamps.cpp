// The measurement grid's nearest detection per cell (MeasurementGrid::nearest, nearest_d2)
// against its per-cell definition: over every detection with finite values, the one whose
// squared distance to the cell centre is the smallest within the cutoff, the lowest index among
// equally near ones. Successive builds of one grid move it, so a cell the last build set and
// this one does not must read -1 again.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "dualgrid/core/random.hpp"
#include "dualgrid/filter/measurement_grid.hpp"

using namespace dualgrid;
using namespace dualgrid::filter;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

std::int64_t Mod(std::int64_t a, std::int64_t b) { return ((a % b) + b) % b; }

struct Nearest {
  int j = -1;
  double d2 = kInf;
};

// The definition for logical cell (lx, ly): every detection, in index order.
Nearest PlainNearest(const FilterParams& fp, const std::array<std::int64_t, 2>& origin, int lx,
                     int ly, const std::vector<Measurement>& z) {
  const double r = fp.resolution;
  const double cutoff = fp.cutoff_sigmas * fp.sigma_f;
  Nearest best;
  for (int j = 0; j < static_cast<int>(z.size()); ++j) {
    if (!z[j].position.allFinite() || !z[j].radial_velocity.allFinite()) continue;
    const double ex = (static_cast<double>(origin[0] + lx) + 0.5) * r - z[j].position.x();
    const double ey = (static_cast<double>(origin[1] + ly) + 0.5) * r - z[j].position.y();
    const double d2 = ex * ex + ey * ey;
    if (d2 <= cutoff * cutoff && d2 < best.d2) best = {j, d2};
  }
  return best;
}

// Detections in clusters around the centre (some exactly repeated: ties), some beyond the grid,
// a few with non-finite values.
std::vector<Measurement> Scene(CounterRng& rng, const Position& centre, const FilterParams& fp) {
  std::vector<Measurement> z;
  const int clusters = static_cast<int>(rng.Uniform(0.0, 40.0));
  for (int c = 0; c < clusters; ++c) {
    const Position at =
        centre + Vector2(rng.Uniform(-0.6, 0.6) * fp.length_x, rng.Uniform(-0.7, 0.7) * fp.width_y);
    const int n = static_cast<int>(rng.Uniform(1.0, 25.0));
    for (int k = 0; k < n; ++k) {
      const bool repeat = !z.empty() && rng.Uniform(0.0, 1.0) < 0.1;
      const Position p =
          repeat ? z.back().position : at + Vector2(rng.Uniform(-3.0, 3.0), rng.Uniform(-1.5, 1.5));
      z.push_back({p, Velocity(rng.Uniform(-1.0, 1.0), 0.0), centre});
    }
  }
  if (!z.empty() && rng.Uniform(0.0, 1.0) < 0.3) z[0].radial_velocity.x() = kInf;
  if (z.size() > 1 && rng.Uniform(0.0, 1.0) < 0.3)
    z[1].position.y() = std::numeric_limits<double>::quiet_NaN();
  return z;
}

}  // namespace

TEST_CASE("every cell's nearest detection is the one of the plain per-cell search",
          "[filter][stamps]") {
  FilterParams fp;  // 200 m x 25 m at 0.5 m, cutoff 1.8 m
  CounterRng rng(37, RngPurpose::kTest, 1, 0);
  const std::vector<SensorCoverage> cov = {{Position(0.0, 0.0), 0.0, 1.0, 0.0, 50.0}};
  std::int64_t cells = 0, stamped = 0, ties = 0;
  for (int run = 0; run < 4; ++run) {
    MeasurementGrid mg(fp);  // one grid over successive, moving builds
    Position centre(rng.Uniform(-1e4, 1e4), rng.Uniform(-1e3, 1e3));
    for (int build = 0; build < 8; ++build) {
      centre += Vector2(rng.Uniform(-3.0, 3.0), rng.Uniform(-3.0, 3.0));  // wraps the storage
      const std::vector<Measurement> z = Scene(rng, centre, fp);
      std::vector<SensorCoverage> c = cov;
      c[0].origin = centre;
      mg.Build(centre, z, c);
      const auto origin = mg.origin_index();
      const int nx = fp.CellsX(), ny = fp.CellsY();
      int wrong = 0;
      for (int ly = 0; ly < ny; ++ly) {
        for (int lx = 0; lx < nx; ++lx) {
          const Nearest want = PlainNearest(fp, origin, lx, ly, z);
          const std::int64_t s = Mod(origin[1] + ly, ny) * nx + Mod(origin[0] + lx, nx);
          wrong += mg.nearest()[s] != want.j;
          // Bit for bit (inf == inf where no detection is near).
          wrong += mg.nearest_d2()[s] != want.d2;
          stamped += want.j >= 0;
          ties += want.j >= 0 && want.j + 1 < static_cast<int>(z.size()) &&
                  z[want.j + 1].position == z[want.j].position;
          ++cells;
        }
      }
      INFO("run " << run << ", build " << build << " with " << z.size() << " detections");
      CHECK(wrong == 0);
    }
  }
  // The scenes stamp a fair share of the cells, and repeated detections tie.
  CHECK(stamped > cells / 50);
  CHECK(ties > 0);
}
