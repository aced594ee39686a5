// The measurement grid's bearing (step 4, the field of view and the ray free space's bins):
// internal to the filter (filter/src/measurement_grid.cpp); public so that tests/filter can hold
// its SIMD lanes to the scalar definition, bit for bit.
#pragma once

namespace dualgrid::filter::detail {

/// atan2(y, x) [rad] by a cubic in the octant, within 2.1e-4 rad of std::atan2 (5e-4 assumed);
/// 0 at the origin.
double FastAtan2(double y, double x);

/// out[i] = FastAtan2(y[i], x[i]) for i in [0, n), on the filter's SIMD lanes (the scalar
/// operations lane by lane): the same bits.
void FastAtan2Lanes(const double* y, const double* x, int n, double* out);

}  // namespace dualgrid::filter::detail
