// Text helpers shared by every library: numbers in messages and files, XML escaping.
//
// Header-only (core is an interface library). Numbers are formatted by the C library in the "C"
// locale (dualgrid never calls setlocale), so outputs are the same on every run and machine.
#pragma once

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <initializer_list>
#include <string>
#include <string_view>

namespace dualgrid {

/// The shortest text that reads back (strtod) as exactly `v`, in printf's %g style: 0.1, 2.5,
/// 1e-07, 3.0000000000000004. Whole numbers below 1e15 are written out (100, not 1e+02);
/// NaN is "nan" (any sign or payload), infinities are "inf" and "-inf". For messages that name a
/// value: the text is the value, not a rounding of it.
inline std::string FormatShort(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0.0 ? "inf" : "-inf";
  char buf[40];
  for (int digits = 1; digits <= 17; ++digits) {  // 17 significant digits always round-trip
    std::snprintf(buf, sizeof buf, "%.*g", digits, v);
    if (std::strtod(buf, nullptr) == v) break;
  }
  // %g turns to an exponent once the exponent reaches the digit count; such a value is whole.
  if (std::strchr(buf, 'e') != nullptr && std::abs(v) >= 1.0 && std::abs(v) < 1e15)
    std::snprintf(buf, sizeof buf, "%.0f", v);
  return buf;
}

/// Several values by FormatShort, in parentheses: "(1.5, -2, nan)" for a point or a pose.
inline std::string FormatTuple(std::initializer_list<double> values) {
  std::string out = "(";
  for (const double v : values) {
    if (out.size() > 1) out += ", ";
    out += FormatShort(v);
  }
  out += ")";
  return out;
}

namespace text_internal {
// printf of one double into a string of the exact length.
inline std::string PrintDouble(const char* format, int precision, double v) {
  const int n = std::snprintf(nullptr, 0, format, precision, v);
  std::string out(static_cast<std::size_t>(n), '\0');
  std::snprintf(out.data(), out.size() + 1, format, precision, v);
  return out;
}
}  // namespace text_internal

/// printf's "%.<digits>g": `digits` significant digits, trailing zeros dropped (1.5, 1e+10,
/// 0.3333). What the SUMO files (10 digits) and regression reports (4 digits) are written with:
/// changing it changes their bytes. NaN and infinities as printf writes them (nan, -nan, inf).
inline std::string FormatSignificant(double v, int digits) {
  return text_internal::PrintDouble("%.*g", digits, v);
}

/// printf's "%.<decimals>f": exactly `decimals` digits after the point (2.50, -0.000, 12), as
/// std::fixed with std::setprecision writes it. NaN and infinities as printf writes them.
inline std::string FormatFixed(double v, int decimals) {
  return text_internal::PrintDouble("%.*f", decimals, v);
}

/// `text` made safe inside an XML attribute value (either quote) or element text: & < > " ' as
/// entities. XML 1.0 cannot hold control characters other than tab, newline and carriage return,
/// even as references: each becomes '?'. Other bytes (UTF-8) are kept as they are.
inline std::string XmlEscape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out +=
            static_cast<unsigned char>(c) < 0x20 && c != '\t' && c != '\n' && c != '\r' ? '?' : c;
    }
  }
  return out;
}

}  // namespace dualgrid
