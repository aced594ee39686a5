// OutsideFov (radar_model/src/scan_geometry.hpp), the scan's field-of-view test without atan2:
// it may reject a point only where the atan2 test it stands in front of rejects it too, so the
// scan's scatterers stay the same bit for bit. Checked on random points and on points placed at
// the edge of the field of view to within a few ulps, where rounding decides.
#include <catch2/catch.hpp>

#include <cmath>

#include "../../radar_model/src/scan_geometry.hpp"
#include "dualgrid/core/random.hpp"

using namespace dualgrid;
using namespace dualgrid::radar::detail;

namespace {

bool AtanOutside(const Position& local, double half_fov) {
  return std::abs(std::atan2(local.y(), local.x())) > half_fov;
}

}  // namespace

TEST_CASE("OutsideFov rejects only points that atan2 puts outside the field of view",
          "[radar][fov]") {
  // 0 and pi: the edges of the range (a sensor that sees all around rejects nothing).
  const double half_fov = GENERATE(0.0, 0.05, 0.1745, 0.6, 1.309, 1.5707963267948966, 2.5, kPi);
  const double bound = FovCosBound(half_fov);
  CounterRng rng(17, RngPurpose::kTest, static_cast<std::uint64_t>(half_fov * 1e6), 0);
  int rejected = 0, atan_outside = 0, far_outside = 0, far_rejected = 0;
  for (int i = 0; i < 20000; ++i) {
    // Half the points at random bearings, half within a few ulps of the edge (either side).
    const double range = rng.Uniform(0.2, 250.0);
    double bearing = rng.Uniform(-kPi, kPi);
    if (i % 2 == 1) {
      bearing = (rng.Uniform() < 0.5 ? -1.0 : 1.0) * half_fov;
      for (int k = static_cast<int>(rng.Uniform(-8.0, 8.0)); k != 0; k += k > 0 ? -1 : 1)
        bearing = std::nextafter(bearing, k > 0 ? 10.0 : -10.0);
    }
    const Position local = range * UnitVector(bearing);
    const bool outside = OutsideFov(local, local.norm(), bound);
    const bool exact = AtanOutside(local, half_fov);
    if (outside) CHECK(exact);  // never a point the atan2 test keeps
    rejected += outside;
    atan_outside += exact;
    // Not vacuous: a point clearly outside (by 1e-4 rad: the margin is 1e-9 in cosine, up to
    // 4.5e-5 rad next to 0 and pi) is rejected without atan2.
    if (std::abs(std::atan2(local.y(), local.x())) > half_fov + 1e-4) {
      ++far_outside;
      far_rejected += outside;
    }
  }
  CHECK(far_rejected == far_outside);
  CHECK(rejected <= atan_outside);
  if (half_fov < kPi) CHECK(far_outside > 0);
}
