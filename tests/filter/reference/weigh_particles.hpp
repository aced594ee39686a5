// Test reference (tests/filter/test_weigh_particles.cpp): the library's WeighParticles as of commit
// 27f8aeb, to check later versions against bit for bit. Not part of the library.
#pragma once

#include "dualgrid/filter/weigh_particles.hpp"

namespace dualgrid::filter_ref {

/// WeighParticles (dualgrid/filter/weigh_particles.hpp) as of 27f8aeb: every candidate of the
/// cell's 3 x 3 buckets, one running minimum.
filter::detail::CellSums WeighParticles(const filter::detail::WeighInputs& in,
                                        const filter::detail::CellParticles& c);

}  // namespace dualgrid::filter_ref
