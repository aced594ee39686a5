#include "dualgrid/outputs/read_back.hpp"

#include <cmath>
#include <stdexcept>

#include "dualgrid/core/input_file.hpp"
#include "dualgrid/core/json_input.hpp"
#include "dualgrid/core/text.hpp"

namespace dualgrid::outputs {

using nlohmann::json;

namespace {

// What a value is, for "found ...": short, and never the value's whole text.
std::string Describe(const json& v) {
  switch (v.type()) {
    case json::value_t::null:
      return "null";
    case json::value_t::boolean:
      return v.get<bool>() ? "true" : "false";
    case json::value_t::number_integer:
    case json::value_t::number_unsigned:
    case json::value_t::number_float:
      return v.dump();
    case json::value_t::string: {
      const std::string& s = v.get_ref<const std::string&>();
      return s.size() <= 40 ? "\"" + s + "\"" : "a text of " + std::to_string(s.size()) + " bytes";
    }
    case json::value_t::array:
      return "a list of " + std::to_string(v.size());
    case json::value_t::object:
      return "an object";
    default:
      return "binary data";
  }
}

std::string Child(const std::string& key, const std::string& name) {
  return key.empty() ? name : key + "." + name;
}

}  // namespace

void JsonAt::Fail(const std::string& expected) const {
  throw std::invalid_argument(*file_ + ": " +
                              (key_.empty() ? "the document" : "key '" + key_ + "'") +
                              ": expected " + expected + ", found " + Describe(*value_));
}

bool JsonAt::Has(const std::string& name) const {
  return value_->is_object() && value_->contains(name);
}

JsonAt JsonAt::operator[](const std::string& name) const {
  if (!value_->is_object()) Fail("an object with the key '" + name + "'");
  const auto it = value_->find(name);
  if (it == value_->end())
    throw std::invalid_argument(*file_ + ": key '" + Child(key_, name) + "': missing");
  return JsonAt(*it, file_, Child(key_, name));
}

std::optional<JsonAt> JsonAt::Find(const std::string& name) const {
  if (!Has(name) || (*value_)[name].is_null()) return std::nullopt;
  return (*this)[name];
}

std::vector<JsonAt> JsonAt::Items(std::size_t max) const {
  if (!value_->is_array()) Fail("a list");
  if (value_->size() > max) Fail("a list of at most " + std::to_string(max));
  std::vector<JsonAt> out;
  out.reserve(value_->size());
  for (std::size_t i = 0; i < value_->size(); ++i)
    out.emplace_back((*value_)[i], file_, key_ + "[" + std::to_string(i) + "]");
  return out;
}

JsonAt JsonAt::Item(std::size_t i) const {
  if (!value_->is_array() || value_->size() <= i) Fail("a list of more than " + std::to_string(i));
  return JsonAt((*value_)[i], file_, key_ + "[" + std::to_string(i) + "]");
}

std::vector<JsonAt> JsonAt::Tuple(std::size_t n) const {
  if (!value_->is_array() || value_->size() != n) Fail("a list of " + std::to_string(n));
  return Items(n);
}

std::vector<std::pair<std::string, JsonAt>> JsonAt::Members() const {
  if (!value_->is_object()) Fail("an object");
  std::vector<std::pair<std::string, JsonAt>> out;
  for (auto it = value_->begin(); it != value_->end(); ++it)
    out.emplace_back(it.key(), JsonAt(it.value(), file_, Child(key_, it.key())));
  return out;
}

double JsonAt::Number(double lo, double hi) const {
  const auto range = [&] {
    return lo <= -1e300 && hi >= 1e300 ? std::string("a finite number")
                                       : "a number in [" + FormatSignificant(lo, 10) + ", " +
                                             FormatSignificant(hi, 10) + "]";
  };
  if (!value_->is_number()) Fail(range());
  const double v = value_->get<double>();
  if (!std::isfinite(v) || v < lo || v > hi) Fail(range());
  return v;
}

std::optional<double> JsonAt::NumberOrNull() const {
  if (value_->is_null()) return std::nullopt;
  if (!value_->is_number() || !std::isfinite(value_->get<double>()))
    Fail("a finite number or null");
  return value_->get<double>();
}

std::int64_t JsonAt::Integer(std::int64_t lo, std::int64_t hi) const {
  const std::string range =
      "a whole number in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  if (value_->is_number_unsigned()) {
    const std::uint64_t u = value_->get<std::uint64_t>();
    if (hi < 0 || u > static_cast<std::uint64_t>(hi)) Fail(range);
    const auto v = static_cast<std::int64_t>(u);
    if (v < lo) Fail(range);
    return v;
  }
  if (!value_->is_number_integer()) Fail(range);
  const std::int64_t v = value_->get<std::int64_t>();
  if (v < lo || v > hi) Fail(range);
  return v;
}

std::uint64_t JsonAt::Unsigned(std::uint64_t hi) const {
  if (!value_->is_number_unsigned() || value_->get<std::uint64_t>() > hi)
    Fail("a whole number in [0, " + std::to_string(hi) + "]");
  return value_->get<std::uint64_t>();
}

std::string JsonAt::Text() const {
  if (!value_->is_string()) Fail("a text");
  return value_->get<std::string>();
}

bool JsonAt::Flag() const {
  if (!value_->is_boolean()) Fail("true or false");
  return value_->get<bool>();
}

JsonFile::JsonFile(json doc, std::string file)
    : doc_(std::make_shared<const json>(std::move(doc))),
      file_(std::make_shared<const std::string>(std::move(file))) {}

JsonFile ParseJsonText(const std::string& text, const std::string& file) {
  return JsonFile(ParseJsonInput(text, file), file);
}

JsonFile ReadJsonFile(const std::filesystem::path& path, const std::string& what,
                      std::uint64_t max_bytes) {
  return JsonFile(ReadJsonInput(path, what, max_bytes), path.string());
}

}  // namespace dualgrid::outputs
