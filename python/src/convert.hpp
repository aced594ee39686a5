// Conversions between Python inputs (numpy arrays, dicts of columns, lists of dicts, tuples) and
// dualgrid's C++ types for the `_dualgrid` extension. Every conversion copies: no C++ object keeps
// a pointer into Python memory. Bad input throws py::value_error (Python's ValueError) naming the
// argument, the expected shape or columns and what was given. Errors of the C++ libraries
// (std::invalid_argument) reach Python as ValueError through pybind11's own translation.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "dualgrid/core/types.hpp"

namespace dualgrid::python {

namespace py = pybind11;

/// One column of a table argument: its name and, for optional columns, the value used when a
/// dict / record omits it.
struct ColumnSpec {
  const char* name;
  std::optional<double> fallback = std::nullopt;
};

/// A row-major table of doubles: rows x columns.size(), values[row * cols + col].
struct Table {
  std::size_t rows = 0;
  std::size_t cols = 0;
  std::vector<double> values;
  double at(std::size_t row, std::size_t col) const { return values[row * cols + col]; }
};

/// Reads table argument `arg` with the given columns from any of:
///  - None or an empty sequence: no rows;
///  - a float array (or nested sequence) of shape (N, columns.size()), columns in that order;
///  - a dict of 1-D columns, a pandas.DataFrame or a numpy structured array, looked up by name
///    (extra columns ignored, so a whole radar detections dict can be passed; optional columns
///    take their fallback when missing);
///  - a list of dicts, one per row (unknown keys are an error: hand-typed records, catch typos).
/// Every value must be finite (ValueError naming the row and column otherwise).
Table ReadTable(py::handle obj, const char* arg, const std::vector<ColumnSpec>& columns);

/// "[a, b, c]" of the column names, for messages.
std::string ColumnList(const std::vector<ColumnSpec>& columns);

/// Reads a fixed-length float vector `arg` (tuple, list or array of `n` finite numbers);
/// `what` describes the entries with units for the error message, e.g. "(x, y, yaw) [m, m, rad]".
std::vector<double> ReadFixed(py::handle obj, const char* arg, std::size_t n, const char* what);
/// (x, y, yaw) [m, m, rad] -> Pose2.
Pose2 ReadPose(py::handle obj, const char* arg);
/// (x, y) -> Vector2, `unit` for the message (e.g. "[m/s]").
Vector2 ReadVector2(py::handle obj, const char* arg, const char* unit);

/// A 1-D numpy array holding a copy of `v`.
template <typename T>
py::array_t<T> ToArray(const std::vector<T>& v) {
  py::array_t<T> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

/// Python's repr of `obj` shortened to ~60 characters, for error messages.
std::string ShortRepr(py::handle obj);

}  // namespace dualgrid::python

namespace dualgrid::python {

/// An argument a function converts itself (a table, a pose, ...), shown in signatures under
/// Tag::name instead of pybind11's "handle" / "object"; the names are the type aliases of the
/// stub (python/dualgrid/_dualgrid.pyi).
template <typename Tag>
struct Arg {
  py::object obj;
  operator py::handle() const { return obj; }
};
// A tag naming an Arg in signatures.
#define DUALGRID_ARG_TAG(Tag, text)                                  \
  struct Tag {                                                       \
    static constexpr auto name = pybind11::detail::const_name(text); \
  }
DUALGRID_ARG_TAG(TableTag, "TableLike");
DUALGRID_ARG_TAG(PoseTag, "PoseLike");
DUALGRID_ARG_TAG(Vector2Tag, "Vector2Like");
DUALGRID_ARG_TAG(ArrayTag, "ArrayLike");
DUALGRID_ARG_TAG(EgoTag, "EgoLike");
DUALGRID_ARG_TAG(SceneTag, "SceneLike");
DUALGRID_ARG_TAG(PolylinesTag, "PolylinesLike");
DUALGRID_ARG_TAG(MultipathTag, "MultipathParams | Mapping[str, Any]");
using MultipathArg = Arg<MultipathTag>;
using TableArg = Arg<TableTag>;
using PolylinesArg = Arg<PolylinesTag>;
using PoseArg = Arg<PoseTag>;
using Vector2Arg = Arg<Vector2Tag>;
using ArrayArg = Arg<ArrayTag>;
using EgoArg = Arg<EgoTag>;
using SceneArg = Arg<SceneTag>;

/// A random seed argument: any Python int in [0, 2**64 - 1]. Another value raises one line naming
/// the argument "seed" (ValueError when out of range, TypeError for a non-integer, bool included),
/// instead of pybind11's list of every overload.
struct Seed {
  std::uint64_t value = 0;
};
/// The seed of an optional `seed` argument (None: the scenario's own).
inline std::optional<std::uint64_t> SeedValue(const std::optional<Seed>& s) {
  return s ? std::optional<std::uint64_t>(s->value) : std::nullopt;
}

}  // namespace dualgrid::python

namespace pybind11::detail {
template <>
struct type_caster<dualgrid::python::Seed> {
  PYBIND11_TYPE_CASTER(dualgrid::python::Seed, const_name("int"));
  bool load(handle src, bool);  // throws value_error / type_error (convert.cpp)
  static handle cast(const dualgrid::python::Seed& v, return_value_policy, handle) {
    return PyLong_FromUnsignedLongLong(v.value);
  }
};

template <typename Tag>
struct type_caster<dualgrid::python::Arg<Tag>> {
  PYBIND11_TYPE_CASTER(dualgrid::python::Arg<Tag>, Tag::name);
  bool load(handle src, bool) {
    value.obj = reinterpret_borrow<object>(src);
    return true;
  }
  static handle cast(const dualgrid::python::Arg<Tag>& v, return_value_policy, handle) {
    return v.obj.inc_ref();
  }
};
}  // namespace pybind11::detail
