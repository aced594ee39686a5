// The Python protocol shared by the bound parameter structs (FilterParams, SensorParams,
// ModelOptions): keyword constructor, to_dict, __repr__, __eq__, copy and pickling, all driven by
// the list of the class's Python properties, so that each field is bound exactly once.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <pybind11/pybind11.h>

namespace dualgrid::python {

namespace py = pybind11;

/// Names of a bound struct's fields in declaration order (filled while binding its properties).
using FieldNames = std::shared_ptr<std::vector<std::string>>;

/// Binds a plain field as a read/write property and records its name.
template <typename T, typename V>
void Field(py::class_<T>& cls, const FieldNames& names, const char* name, V T::*member,
           const char* doc) {
  cls.def_readwrite(name, member, doc);
  names->push_back(name);
}

/// Sets every keyword of `kwargs` as a field of `value` through its Python property (so setters
/// that parse or check run); TypeError for a name that is not a field, as Python does for an
/// unknown keyword.
template <typename T>
void SetFields(T& value, const py::dict& kwargs, const FieldNames& names, const char* type) {
  py::object self = py::cast(&value, py::return_value_policy::reference);
  for (auto item : kwargs) {
    const std::string key = std::string(py::str(item.first));
    bool known = false;
    for (const std::string& n : *names) known = known || n == key;
    if (!known) {
      std::string list;
      for (const std::string& n : *names) list += (list.empty() ? "" : ", ") + n;
      throw py::type_error(std::string(type) + ": unknown field '" + key + "' (fields: " + list +
                           ")");
    }
    py::setattr(self, py::str(key), item.second);
  }
}

/// Adds __init__(**fields), to_dict(), __repr__, __eq__, __copy__, __deepcopy__ and pickling.
/// Call after binding the properties named in `names`.
template <typename T>
void AddValueProtocol(py::class_<T>& cls, const FieldNames& names, const char* type) {
  cls.def(py::init([names, type](const py::kwargs& kwargs) {
            T value;
            SetFields(value, kwargs, names, type);
            return value;
          }),
          "Defaults of the C++ struct, then every keyword set as a field (TypeError for an "
          "unknown name, ValueError for a bad value of a checked field).");
  const auto to_dict = [names](const T& value) {
    // Through the Python properties (so enum fields read as their names), on a view of `value`.
    py::object self = py::cast(&value, py::return_value_policy::reference);
    py::dict d;
    for (const std::string& n : *names) {
      py::object v = self.attr(py::str(n));
      // A nested parameter struct (ModelOptions.multipath) as its own dict: plain data.
      d[py::str(n)] = py::hasattr(v, "to_dict") ? v.attr("to_dict")() : v;
    }
    return d;
  };
  cls.def("to_dict", to_dict, "Every field as {name: value} (a copy).");
  cls.def("__repr__", [to_dict, type](const T& self) {
    std::string s = std::string(type) + "(";
    bool first = true;
    for (auto item : to_dict(self)) {
      s += (first ? "" : ", ") + std::string(py::str(item.first)) + "=" +
           std::string(py::repr(item.second));
      first = false;
    }
    return s + ")";
  });
  cls.def(
      "__eq__",
      [to_dict](const T& self, py::object other) -> py::object {
        if (!py::isinstance<T>(other)) return py::reinterpret_borrow<py::object>(Py_NotImplemented);
        return py::bool_(to_dict(self).equal(to_dict(other.cast<const T&>())));
      },
      py::arg("other"));
  cls.attr("__hash__") = py::none();  // mutable
  cls.def("__copy__", [](const T& v) { return T(v); });
  cls.def(
      "__deepcopy__", [](const T& v, py::dict) { return T(v); }, py::arg("memo"));
  cls.def(py::pickle([to_dict](const T& self) { return to_dict(self); },
                     [names, type](py::dict d) {
                       T value;
                       SetFields(value, d, names, type);
                       return value;
                     }));
}

}  // namespace dualgrid::python
