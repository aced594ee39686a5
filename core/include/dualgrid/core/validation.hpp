// Parameter validation: the one way every IsValid(std::string* error) builds its message.
//
// A FieldCheck runs checks in order and keeps the FIRST failure; checks after it do nothing, so a
// check may rely on earlier ones (`length_x >= resolution` after `resolution > 0`). Each message
// names the field (with the checker's prefix), the value given and what was expected:
//
//     sigma_v = -1: expected finite and > 0
//     persistence = nan: expected in (0, 1]
//     association.center_gate = 0: expected finite and > 0    (a nested struct, via Member)
//
// Numbers are written by FormatShort (core/text.hpp): the text reads back as the value given,
// NaN is "nan" and infinities "inf"/"-inf". NaN fails every numeric check.
//
//   bool Params::IsValid(std::string* error) const {
//     FieldCheck c;
//     c.Positive("sigma_v", sigma_v);
//     c.InRange("persistence", persistence, 0.0, 1.0, Interval::kLeftOpen);
//     c.AtLeast("num_particles", num_particles, 1);
//     c.Expect(max_range > min_range, "max_range", max_range, "> min_range = " + ...);
//     c.Member("association.", association);
//     for (std::size_t i = 0; i < sizes.size(); ++i) c.Positive(Indexed("sizes", i), sizes[i]);
//     return c.Done(error);  // false and *error = the first message, or true and *error untouched
//   }
#pragma once

#include <cmath>
#include <concepts>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>

#include "dualgrid/core/text.hpp"

namespace dualgrid {

/// The field name of element `i` of a list: "name[i]".
inline std::string Indexed(std::string_view name, std::size_t i) {
  std::string out(name);
  out.append("[").append(std::to_string(i)).append("]");
  return out;
}

/// Which ends of an InRange interval belong to it: [lo, hi], (lo, hi), (lo, hi], [lo, hi).
enum class Interval { kClosed, kOpen, kLeftOpen, kRightOpen };

/// True when `v` lies in the interval from `lo` to `hi`, ends included as `ends` says (NaN never).
inline bool InInterval(double v, double lo, double hi, Interval ends) {
  const bool open_lo = ends == Interval::kOpen || ends == Interval::kLeftOpen;
  const bool open_hi = ends == Interval::kOpen || ends == Interval::kRightOpen;
  return (open_lo ? v > lo : v >= lo) && (open_hi ? v < hi : v <= hi);
}

/// The interval as messages write it: "in (0, 30]".
inline std::string IntervalText(double lo, double hi, Interval ends) {
  const bool open_lo = ends == Interval::kOpen || ends == Interval::kLeftOpen;
  const bool open_hi = ends == Interval::kOpen || ends == Interval::kRightOpen;
  return std::string("in ") + (open_lo ? "(" : "[") + FormatShort(lo) + ", " + FormatShort(hi) +
         (open_hi ? ")" : "]");
}

class FieldCheck {
 public:
  /// `prefix` is put before every field name, e.g. "series[2]." for the elements of a list.
  explicit FieldCheck(std::string prefix = {}) : prefix_(std::move(prefix)) {}

  /// The general check: fails with "<field> = <value>: expected <expected>" unless `ok`.
  /// `value` is the value as text (a name in quotes, a count with its unit, ...).
  FieldCheck& Expect(bool ok, std::string_view field, std::string_view value,
                     std::string_view expected) {
    if (!ok && ok_) {
      ok_ = false;
      message_ = prefix_;
      message_.append(field).append(" = ").append(value).append(": expected ").append(expected);
    }
    return *this;
  }
  /// As above with a number, written by FormatShort.
  FieldCheck& Expect(bool ok, std::string_view field, double value, std::string_view expected) {
    return ok || !ok_ ? *this : Expect(false, field, FormatShort(value), expected);
  }

  /// Not NaN nor infinite. `unit` (e.g. "m") is appended to the expectation.
  FieldCheck& Finite(std::string_view field, double v, std::string_view unit = {}) {
    return Expect(std::isfinite(v), field, v, WithUnit("finite", unit));
  }
  /// Finite and > 0.
  FieldCheck& Positive(std::string_view field, double v, std::string_view unit = {}) {
    return Expect(std::isfinite(v) && v > 0.0, field, v, WithUnit("finite and > 0", unit));
  }
  /// Finite and >= 0.
  FieldCheck& NonNegative(std::string_view field, double v, std::string_view unit = {}) {
    return Expect(std::isfinite(v) && v >= 0.0, field, v, WithUnit("finite and >= 0", unit));
  }
  /// In the interval from `lo` to `hi` (finite bounds), ends included as `ends` says.
  FieldCheck& InRange(std::string_view field, double v, double lo, double hi,
                      Interval ends = Interval::kClosed, std::string_view unit = {}) {
    if (InInterval(v, lo, hi, ends) || !ok_) return *this;
    return Expect(false, field, v, WithUnit(IntervalText(lo, hi, ends), unit));
  }

  /// Integers: at least `lo`.
  template <std::integral T>
  FieldCheck& AtLeast(std::string_view field, T v, std::type_identity_t<T> lo) {
    return Expect(v >= lo, field, std::to_string(v), ">= " + std::to_string(lo));
  }
  /// Integers: in [lo, hi].
  template <std::integral T>
  FieldCheck& InRange(std::string_view field, T v, std::type_identity_t<T> lo,
                      std::type_identity_t<T> hi) {
    return Expect(v >= lo && v <= hi, field, std::to_string(v),
                  "in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  }

  /// A nested struct with its own IsValid(std::string*): its message with `prefix` (and this
  /// checker's) before it, e.g. Member("association.", association).
  template <typename T>
  FieldCheck& Member(std::string_view prefix, const T& member) {
    std::string inner;
    if (ok_ && !member.IsValid(&inner)) {
      ok_ = false;
      message_ = prefix_;
      message_.append(prefix).append(inner);
    }
    return *this;
  }

  bool ok() const { return ok_; }
  /// The first failure's message; empty while every check passed.
  const std::string& message() const { return message_; }

  /// The result for IsValid: true when every check passed (leaving *error untouched), otherwise
  /// false with the first failure's message in *error (if `error` is not null).
  bool Done(std::string* error) const {
    if (!ok_ && error != nullptr) *error = message_;
    return ok_;
  }

 private:
  static std::string WithUnit(std::string expected, std::string_view unit) {
    if (!unit.empty()) expected.append(" ").append(unit);
    return expected;
  }

  std::string prefix_;
  bool ok_ = true;
  std::string message_;
};

}  // namespace dualgrid
