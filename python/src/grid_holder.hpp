// The Python DynamicGrid: the C++ grid and the lock that serialises calls from different Python
// threads (update() runs without the GIL, so another thread could otherwise read the grid while
// it changes). Shared by filter_bindings.cpp (the class) and eval_bindings.cpp (its particles).
#pragma once

#include <cstdint>
#include <mutex>

#include <pybind11/pybind11.h>

#include "dualgrid/filter/dynamic_grid.hpp"

namespace dualgrid::python {

struct Grid {
  Grid(const filter::FilterParams& params, std::uint64_t seed) : grid(params, seed) {}
  filter::DynamicGrid grid;
  std::mutex mutex;
};

/// Runs f(grid) without the GIL under the grid's lock. f must not touch Python objects (it may
/// write into numpy buffers allocated before, which no other thread can see yet).
template <typename F>
auto Locked(Grid& g, F&& f) {
  pybind11::gil_scoped_release nogil;
  std::lock_guard<std::mutex> lock(g.mutex);
  return f(g.grid);
}

}  // namespace dualgrid::python
