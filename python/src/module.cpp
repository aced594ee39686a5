// The `_dualgrid` extension module: the filter and the radar model for Python (docs/python.md).
// The pure-Python package dualgrid/ (python/dualgrid/__init__.py) re-exports everything here.
#include <atomic>
#include <string>

#include <omp.h>

#include <pybind11/pybind11.h>

#include "bindings.hpp"
#include "dualgrid/core/limits.hpp"

namespace dualgrid::python {
namespace {

// 0: leave OpenMP's own choice (OMP_NUM_THREADS or all cores).
std::atomic<int> g_num_threads{0};

}  // namespace

int CheckThreads(int n, const char* fn, const char* key) {
  // The command line's bound (--threads: core/limits.hpp); a huge team exhausts the stacks of
  // OpenMP's thread pool and ends the interpreter.
  if (n < 0 || n > MaxThreads())
    throw py::value_error(std::string(fn) + ": " + key + " must be >= 0 and <= " +
                          std::to_string(MaxThreads()) + " (" + std::to_string(kMaxThreadsPerCore) +
                          " per core, as --threads), got " + std::to_string(n));
  return n;
}

void ApplyThreadCount() {
  const int n = g_num_threads.load();
  if (n > 0) omp_set_num_threads(n);
}

}  // namespace dualgrid::python

PYBIND11_MODULE(_dualgrid, m) {
  namespace py = pybind11;
  using namespace dualgrid::python;
  m.doc() =
      "dualgrid: radar-only dual-weight particle-filter dynamic occupancy grid and the radar "
      "model (compiled part; import the package `dualgrid`).";
  m.attr("__version__") = DUALGRID_VERSION;

  m.def(
      "set_num_threads", [](int n) { g_num_threads = CheckThreads(n, "set_num_threads", "n"); },
      py::arg("n"),
      "Threads of the parallel C++ stages (grid update, radar scan) for every later call from any "
      "Python thread, at most 4 per core (as --threads; ValueError beyond); 0 restores OpenMP's "
      "default (OMP_NUM_THREADS or all cores). Results do not "
      "depend on it.");
  m.def(
      "get_num_threads",
      []() {
        const int n = g_num_threads.load();
        return n > 0 ? n : omp_get_max_threads();
      },
      "Threads the next parallel C++ stage will use.");

  BindFilter(m);
  BindRadar(m);

  BindCosim(m);
  BindRecorded(m);
  BindNuScenes(m);
  BindStepping(m);
  BindEval(m);
}
