#include <cstdio>
#include <cstdlib>
#include <regex>

#include "dualgrid/core/text.hpp"
#include "dualgrid/core/types.hpp"
#include "sections.hpp"

namespace dualgrid::scenario::detail {

std::string Shown(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

namespace {

// A validator's expectation in radians as degrees: "2 pi" and "pi" as numbers, the ends of
// "in (a, b] rad" converted, "rad" -> "deg".
std::string InDegrees(std::string text) {
  text = std::regex_replace(text, std::regex(R"(\b2 pi\b)"), "6.283185307179586");
  text = std::regex_replace(text, std::regex(R"(\bpi\b)"), "3.141592653589793");
  static const std::regex kInterval(R"(in ([\[(])([^,]+), ([^\])]+)([\])]) rad)");
  std::string out;
  std::sregex_iterator it(text.begin(), text.end(), kInterval), end;
  std::size_t done = 0;
  for (; it != end; ++it) {
    const std::smatch& m = *it;
    out += text.substr(done, m.position() - done) + "in " + m[1].str() +
           FormatShort(RadToDeg(std::strtod(m[2].str().c_str(), nullptr))) + ", " +
           FormatShort(RadToDeg(std::strtod(m[3].str().c_str(), nullptr))) + m[4].str() + " deg";
    done = m.position() + m.length();
  }
  out += text.substr(done);
  return std::regex_replace(out, std::regex(R"(\brad\b)"), "deg");
}

}  // namespace

[[noreturn]] void Invalid(const std::string& file, const std::string& section,
                          const std::string& error, std::span<const KeyAlias> aliases) {
  const auto key = [&](const std::string& field) {
    return file + ": key '" + (section.empty() ? field : section + "." + field) + "' ";
  };
  auto colon = error.find(": ");
  const auto equals = error.find(" = ");
  if (equals != std::string::npos && equals < colon) {
    const auto expected = error.find(": expected ", equals);
    if (expected != std::string::npos) {
      std::string field = error.substr(0, equals), what = error.substr(expected + 11),
                  value = error.substr(equals + 3, expected - equals - 3);
      for (const KeyAlias& a : aliases) {
        if (field != a.field) continue;
        field = std::string(a.key);
        if (a.degrees) {
          char* end = nullptr;
          const double rad = std::strtod(value.c_str(), &end);
          if (end != value.c_str() && *end == '\0') value = FormatShort(RadToDeg(rad)) + " deg";
          what = InDegrees(what);
        }
        break;
      }
      throw ConfigError(key(field) + "expected " + what + ", got " + value);
    }
  }
  std::size_t skip = 2;
  if (colon == std::string::npos) colon = error.find(' '), skip = 1;
  const std::string field = colon == std::string::npos ? error : error.substr(0, colon);
  const std::string message =
      colon == std::string::npos ? "is invalid" : error.substr(colon + skip);
  throw ConfigError(key(field) + message);
}

}  // namespace dualgrid::scenario::detail
