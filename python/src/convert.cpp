#include "convert.hpp"

#include <cmath>
#include <string>

namespace dualgrid::python {

std::string ShortRepr(py::handle obj) {
  std::string s = py::repr(obj).cast<std::string>();
  if (s.size() > 60) s = s.substr(0, 57) + "...";
  return s;
}

std::string ColumnList(const std::vector<ColumnSpec>& columns) {
  std::string s = "[";
  for (std::size_t c = 0; c < columns.size(); ++c)
    s += (c ? ", " : "") + std::string(columns[c].name);
  return s + "]";
}

namespace {

std::string ShapeOf(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t d = 0; d < a.ndim(); ++d) s += (d ? ", " : "") + std::to_string(a.shape(d));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

// np.asarray(obj, dtype=float64) as a C-contiguous array; ValueError naming `what` on failure
// (strings, ragged lists).
py::array_t<double, py::array::c_style | py::array::forcecast> AsFloatArray(
    py::handle obj, const std::string& what) {
  try {
    py::object a = py::module_::import("numpy").attr("ascontiguousarray")(obj, "float64");
    return a.cast<py::array_t<double, py::array::c_style | py::array::forcecast>>();
  } catch (py::error_already_set& e) {
    throw py::value_error(what + ": cannot convert " + ShortRepr(obj) + " to a float array (" +
                          e.what() + ")");
  }
}

void CheckFinite(const Table& t, const char* arg, const std::vector<ColumnSpec>& columns) {
  for (std::size_t r = 0; r < t.rows; ++r)
    for (std::size_t c = 0; c < t.cols; ++c)
      if (!std::isfinite(t.at(r, c)))
        throw py::value_error(std::string(arg) + ": row " + std::to_string(r) + ", column '" +
                              columns[c].name + "' is not finite (" + std::to_string(t.at(r, c)) +
                              ")");
}

bool IsMapping(py::handle obj) {
  return py::isinstance(obj, py::module_::import("collections.abc").attr("Mapping"));
}

// Dict of columns, DataFrame or structured array: look every column up by name.
Table ReadByName(py::handle obj, const char* arg, const std::vector<ColumnSpec>& columns,
                 bool has_key_method) {
  Table t;
  t.cols = columns.size();
  std::vector<py::array_t<double, py::array::c_style | py::array::forcecast>> cols(t.cols);
  std::vector<bool> present_col(t.cols, false);
  std::optional<std::size_t> rows;
  for (std::size_t c = 0; c < t.cols; ++c) {
    const char* name = columns[c].name;
    bool present;
    if (has_key_method) {
      present = obj.attr("__contains__")(name).cast<bool>();
    } else {  // structured array
      py::object names = obj.attr("dtype").attr("names");
      present = names.attr("__contains__")(name).cast<bool>();
    }
    if (!present) {
      if (columns[c].fallback) continue;
      throw py::value_error(std::string(arg) + ": missing column '" + name + "' (expected " +
                            ColumnList(columns) + ")");
    }
    cols[c] = AsFloatArray(obj[py::str(name)], std::string(arg) + "['" + name + "']");
    present_col[c] = true;
    if (cols[c].ndim() != 1)
      throw py::value_error(std::string(arg) + "['" + name +
                            "']: expected a 1-D column, got shape " + ShapeOf(cols[c]));
    const auto n = static_cast<std::size_t>(cols[c].shape(0));
    if (rows && *rows != n)
      throw py::value_error(std::string(arg) + ": columns of different lengths (" +
                            std::to_string(*rows) + " and " + std::to_string(n) + " for '" + name +
                            "')");
    rows = n;
  }
  t.rows = rows.value_or(0);
  t.values.resize(t.rows * t.cols);
  for (std::size_t c = 0; c < t.cols; ++c) {
    for (std::size_t r = 0; r < t.rows; ++r)
      t.values[r * t.cols + c] = present_col[c] ? cols[c].data()[r] : *columns[c].fallback;
  }
  return t;
}

// List of dicts: one record per row.
Table ReadRecords(py::sequence seq, const char* arg, const std::vector<ColumnSpec>& columns) {
  Table t;
  t.cols = columns.size();
  t.rows = seq.size();
  t.values.resize(t.rows * t.cols);
  for (std::size_t r = 0; r < t.rows; ++r) {
    py::handle rec = seq[r];
    const std::string where = std::string(arg) + "[" + std::to_string(r) + "]";
    if (!IsMapping(rec))
      throw py::value_error(where + ": expected a dict with keys " + ColumnList(columns) +
                            ", got " + ShortRepr(rec));
    py::dict d = py::dict(py::reinterpret_borrow<py::object>(rec));
    for (auto item : d) {
      const std::string key = py::str(item.first).cast<std::string>();
      bool known = false;
      for (const ColumnSpec& c : columns) known = known || key == c.name;
      if (!known)
        throw py::value_error(where + ": unknown key '" + key + "' (expected " +
                              ColumnList(columns) + ")");
    }
    for (std::size_t c = 0; c < t.cols; ++c) {
      const char* name = columns[c].name;
      double v;
      if (d.contains(name)) {
        try {
          v = d[name].cast<double>();
        } catch (py::cast_error&) {
          throw py::value_error(where + "['" + name + "']: expected a number, got " +
                                ShortRepr(d[name]));
        }
      } else if (columns[c].fallback) {
        v = *columns[c].fallback;
      } else {
        throw py::value_error(where + ": missing key '" + name + "' (expected " +
                              ColumnList(columns) + ")");
      }
      t.values[r * t.cols + c] = v;
    }
  }
  return t;
}

}  // namespace

Table ReadTable(py::handle obj, const char* arg, const std::vector<ColumnSpec>& columns) {
  Table t;
  t.cols = columns.size();
  if (obj.is_none()) return t;
  const bool is_array = py::isinstance<py::array>(obj);
  if (is_array && !obj.attr("dtype").attr("names").is_none()) {
    t = ReadByName(obj, arg, columns, false);
  } else if (!is_array && (IsMapping(obj) || py::hasattr(obj, "columns"))) {  // dict, DataFrame
    t = ReadByName(obj, arg, columns, true);
  } else if (!is_array && py::isinstance<py::sequence>(obj) && !py::isinstance<py::str>(obj) &&
             py::len(obj) > 0 &&
             IsMapping(py::sequence(py::reinterpret_borrow<py::object>(obj))[0])) {
    t = ReadRecords(py::reinterpret_borrow<py::sequence>(obj), arg, columns);
  } else {
    const auto a = AsFloatArray(obj, arg);
    if (a.size() == 0 && a.ndim() <= 2 &&
        (a.ndim() < 2 || a.shape(1) == 0 || a.shape(1) == static_cast<py::ssize_t>(t.cols)))
      return t;  // [], np.empty((0, C)), np.empty((0, 0))
    if (a.ndim() != 2 || a.shape(1) != static_cast<py::ssize_t>(t.cols))
      throw py::value_error(std::string(arg) + ": expected a float array of shape (N, " +
                            std::to_string(t.cols) + ") with columns " + ColumnList(columns) +
                            ", got shape " + ShapeOf(a));
    t.rows = static_cast<std::size_t>(a.shape(0));
    t.values.assign(a.data(), a.data() + a.size());
  }
  CheckFinite(t, arg, columns);
  return t;
}

std::vector<double> ReadFixed(py::handle obj, const char* arg, std::size_t n, const char* what) {
  const auto a = AsFloatArray(obj, arg);
  if (a.ndim() != 1 || a.shape(0) != static_cast<py::ssize_t>(n))
    throw py::value_error(std::string(arg) + ": expected " + what + ", got " + ShortRepr(obj));
  std::vector<double> v(a.data(), a.data() + n);
  for (double x : v)
    if (!std::isfinite(x))
      throw py::value_error(std::string(arg) + ": expected finite " + what + ", got " +
                            ShortRepr(obj));
  return v;
}

Pose2 ReadPose(py::handle obj, const char* arg) {
  const auto v = ReadFixed(obj, arg, 3, "(x, y, yaw) [m, m, rad]");
  return Pose2{Position(v[0], v[1]), v[2]};
}

Vector2 ReadVector2(py::handle obj, const char* arg, const char* unit) {
  const std::string what = std::string("(x, y) ") + unit;
  const auto v = ReadFixed(obj, arg, 2, what.c_str());
  return {v[0], v[1]};
}

}  // namespace dualgrid::python

namespace pybind11::detail {

bool type_caster<dualgrid::python::Seed>::load(handle src, bool) {
  constexpr const char* kExpected = "seed: expected an integer in [0, 2**64 - 1], got ";
  if (!PyLong_Check(src.ptr()) || PyBool_Check(src.ptr()))
    throw type_error(kExpected + std::string(Py_TYPE(src.ptr())->tp_name));
  const unsigned long long v = PyLong_AsUnsignedLongLong(src.ptr());
  if (v == static_cast<unsigned long long>(-1) && PyErr_Occurred()) {
    PyErr_Clear();  // negative or too large: our message instead of Python's
    throw value_error(kExpected + std::string(str(src)));
  }
  value.value = v;
  return true;
}

}  // namespace pybind11::detail
