#include <cstdio>

#include "sections.hpp"

namespace dualgrid::scenario::detail {

std::string Shown(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// Turns an IsValid message into a ConfigError naming the key under `section`. FieldCheck
// messages, "field = value: expected what", read as the parser's own: "key '<section>.field'
// expected what, got value"; other validators write "field: message" or "field message".
[[noreturn]] void Invalid(const std::string& file, const std::string& section,
                          const std::string& error) {
  const auto key = [&](const std::string& field) {
    return file + ": key '" + (section.empty() ? field : section + "." + field) + "' ";
  };
  auto colon = error.find(": ");
  const auto equals = error.find(" = ");
  if (equals != std::string::npos && equals < colon) {
    const auto expected = error.find(": expected ", equals);
    if (expected != std::string::npos)
      throw ConfigError(key(error.substr(0, equals)) + "expected " + error.substr(expected + 11) +
                        ", got " + error.substr(equals + 3, expected - equals - 3));
  }
  std::size_t skip = 2;
  if (colon == std::string::npos) colon = error.find(' '), skip = 1;
  const std::string field = colon == std::string::npos ? error : error.substr(0, colon);
  const std::string message =
      colon == std::string::npos ? "is invalid" : error.substr(colon + skip);
  throw ConfigError(key(field) + message);
}

}  // namespace dualgrid::scenario::detail
