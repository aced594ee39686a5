// The filter's own particle state (internal): float structure of arrays in grid-local metres,
// 64-byte aligned. docs/algorithm.md, "Float state".
#pragma once

#include <cstddef>
#include <cstdint>
#include <new>
#include <vector>

#include "dualgrid/filter/particles.hpp"

namespace dualgrid::filter::detail {

/// std::allocator with 64-byte alignment (one cache line; whole SIMD vectors of any x86 width).
template <typename T>
struct AlignedAllocator {
  using value_type = T;
  static constexpr std::align_val_t kAlign{64};
  AlignedAllocator() = default;
  template <typename U>
  AlignedAllocator(const AlignedAllocator<U>&) {}
  T* allocate(std::size_t n) { return static_cast<T*>(::operator new(n * sizeof(T), kAlign)); }
  void deallocate(T* p, std::size_t) { ::operator delete(p, kAlign); }
  template <typename U>
  bool operator==(const AlignedAllocator<U>&) const {
    return true;
  }
};

template <typename T>
using AlignedVector = std::vector<T, AlignedAllocator<T>>;

/// Particles of a DynamicGrid. x, y [m]: position relative to the corner of the grid's logical
/// cell (0, 0) (the caller's frame position is (origin_gx r + x, origin_gy r + y)), so a
/// particle's cell is (floor(x / r), floor(y / r)) and a shift of the grid by k whole cells
/// subtracts k r. vx, vy [m/s] in the caller's frame; the weights as ParticleSet's.
struct LocalParticles {
  AlignedVector<float> x, y, vx, vy, w_position, w_velocity, weight;

  std::size_t size() const { return x.size(); }
  void resize(std::size_t n) {
    for (auto* v : {&x, &y, &vx, &vy, &w_position, &w_velocity, &weight}) v->resize(n);
  }
  void CopyFrom(const LocalParticles& src, std::size_t i, std::size_t k) {
    CopyParticle(src, i, *this, k);
  }
};

}  // namespace dualgrid::filter::detail
