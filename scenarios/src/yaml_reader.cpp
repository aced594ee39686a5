#include "yaml_reader.hpp"

#include <cmath>

namespace dualgrid::scenario {
namespace {

std::string Show(const YAML::Node& n) {
  if (n.IsScalar()) return "'" + n.Scalar() + "'";
  if (n.IsSequence()) return "a list";
  if (n.IsMap()) return "a map";
  return "nothing";
}

// Text goes into JSON and SUMO's XML, both UTF-8 only.
bool ValidUtf8(const std::string& s) {
  for (std::size_t i = 0; i < s.size();) {
    const auto c = static_cast<unsigned char>(s[i]);
    std::size_t extra = 0;  // continuation bytes after the lead byte
    if (c >= 0x80) {
      if ((c >> 5) == 0x6)
        extra = 1;
      else if ((c >> 4) == 0xE)
        extra = 2;
      else if ((c >> 3) == 0x1E)
        extra = 3;
      else
        return false;
    }
    if (i + extra >= s.size() && extra > 0) return false;
    for (std::size_t k = 1; k <= extra; ++k)
      if ((static_cast<unsigned char>(s[i + k]) >> 6) != 0x2) return false;
    i += 1 + extra;
  }
  return true;
}

}  // namespace

MapReader::MapReader(YAML::Node node, std::string file, std::string path)
    : node_(std::move(node)), file_(std::move(file)), path_(std::move(path)) {
  if (!node_.IsMap()) {
    throw ConfigError(file_ + ": key '" + (path_.empty() ? "<document>" : path_) +
                      "': expected a map of settings, got " + Show(node_));
  }
  // yaml-cpp keeps one of two equal keys without a word; a repeated key is almost always an
  // edit that left the old value behind, so it is an error naming the line of the second.
  std::set<std::string> seen;
  for (const auto& kv : node_) {
    if (!kv.first.IsScalar()) continue;  // reported where the key is read
    if (!ValidUtf8(kv.first.Scalar()))
      throw ConfigError(file_ + ":" + std::to_string(kv.first.Mark().line + 1) + ": a key of '" +
                        (path_.empty() ? "<document>" : path_) + "' is not valid UTF-8 text");
    if (!seen.insert(kv.first.Scalar()).second)
      throw ConfigError(file_ + ":" + std::to_string(kv.first.Mark().line + 1) + ": key '" +
                        KeyPath(kv.first.Scalar()) + "' appears twice in the same map");
  }
}

std::string MapReader::KeyPath(const std::string& key) const {
  return path_.empty() ? key : path_ + "." + key;
}

void MapReader::Fail(const std::string& key, const std::string& expected) const {
  throw ConfigError(file_ + ": key '" + KeyPath(key) + "' " + expected);
}

bool MapReader::Has(const std::string& key) {
  known_.insert(key);
  return static_cast<bool>(node_[key]);
}

bool MapReader::IsMap(const std::string& key) { return Has(key) && node_[key].IsMap(); }

YAML::Node MapReader::Get(const std::string& key) {
  known_.insert(key);
  return node_[key];
}

double MapReader::ToDouble(const YAML::Node& n, const std::string& key) const {
  double v = 0.0;
  if (!n.IsScalar() || !YAML::convert<double>::decode(n, v) || !std::isfinite(v))
    Fail(key, "expected a number, got " + Show(n));
  return v;
}

void MapReader::Read(const std::string& key, double* out) {
  if (auto n = Get(key)) *out = ToDouble(n, key);
}

void MapReader::Read(const std::string& key, std::optional<double>* out) {
  if (auto n = Get(key)) *out = ToDouble(n, key);
}

void MapReader::Read(const std::string& key, int* out) {
  if (auto n = Get(key)) {
    long long v = 0;
    if (!n.IsScalar() || !YAML::convert<long long>::decode(n, v) || v < INT32_MIN || v > INT32_MAX)
      Fail(key, "expected an integer, got " + Show(n));
    *out = static_cast<int>(v);
  }
}

void MapReader::Read(const std::string& key, std::optional<int>* out) {
  if (Has(key)) {
    int v = 0;
    Read(key, &v);
    *out = v;
  }
}

void MapReader::Read(const std::string& key, std::uint64_t* out) {
  if (auto n = Get(key)) {
    unsigned long long v = 0;
    if (!n.IsScalar() || n.Scalar().find('-') != std::string::npos ||
        !YAML::convert<unsigned long long>::decode(n, v))
      Fail(key, "expected a non-negative integer, got " + Show(n));
    *out = v;
  }
}

void MapReader::Read(const std::string& key, bool* out) {
  if (auto n = Get(key)) {
    bool v = false;
    if (!n.IsScalar() || !YAML::convert<bool>::decode(n, v))
      Fail(key, "expected true or false, got " + Show(n));
    *out = v;
  }
}

void MapReader::Read(const std::string& key, std::string* out) {
  if (auto n = Get(key)) {
    if (!n.IsScalar()) Fail(key, "expected a text value, got " + Show(n));
    if (!ValidUtf8(n.Scalar())) Fail(key, "is not valid UTF-8 text");
    *out = n.Scalar();
  }
}

void MapReader::ReadDegrees(const std::string& key, double* out_rad) {
  if (auto n = Get(key)) *out_rad = DegToRad(ToDouble(n, key));
}

void MapReader::Read(const std::string& key, Position* out) {
  if (auto n = Get(key)) {
    if (!n.IsSequence() || n.size() != 2)
      Fail(key, "expected a point [x, y] in metres, got " + Show(n));
    *out = Position(ToDouble(n[0], key), ToDouble(n[1], key));
  }
}

void MapReader::Read(const std::string& key, std::vector<Position>* out) {
  if (auto n = Get(key)) {
    if (!n.IsSequence()) Fail(key, "expected a list of points [[x, y], ...], got " + Show(n));
    out->clear();
    for (std::size_t i = 0; i < n.size(); ++i) {
      const auto& p = n[i];
      if (!p.IsSequence() || p.size() != 2)
        Fail(key + "[" + std::to_string(i) + "]",
             "expected a point [x, y] in metres, got " + Show(p));
      out->emplace_back(ToDouble(p[0], key), ToDouble(p[1], key));
    }
  }
}

void MapReader::Read(const std::string& key, std::vector<std::string>* out) {
  if (auto n = Get(key)) {
    if (!n.IsSequence()) Fail(key, "expected a list of names, got " + Show(n));
    out->clear();
    for (std::size_t i = 0; i < n.size(); ++i) {
      if (!n[i].IsScalar())
        Fail(key + "[" + std::to_string(i) + "]", "expected a name, got " + Show(n[i]));
      if (!ValidUtf8(n[i].Scalar()))
        Fail(key + "[" + std::to_string(i) + "]", "is not valid UTF-8 text");
      out->push_back(n[i].Scalar());
    }
  }
}

void MapReader::Read(const std::string& key, std::vector<double>* out) {
  if (auto n = Get(key)) {
    if (!n.IsSequence()) Fail(key, "expected a list of numbers, got " + Show(n));
    out->clear();
    for (std::size_t i = 0; i < n.size(); ++i) out->push_back(ToDouble(n[i], key));
  }
}

std::optional<MapReader> MapReader::Map(const std::string& key) {
  auto n = Get(key);
  if (!n) return std::nullopt;
  return MapReader(n, file_, KeyPath(key));
}

std::vector<MapReader> MapReader::MapList(const std::string& key) {
  std::vector<MapReader> out;
  auto n = Get(key);
  if (!n) return out;
  if (!n.IsSequence()) Fail(key, "expected a list, got " + Show(n));
  for (std::size_t i = 0; i < n.size(); ++i)
    out.emplace_back(n[i], file_, KeyPath(key) + "[" + std::to_string(i) + "]");
  return out;
}

std::vector<std::pair<std::string, MapReader>> MapReader::NamedMaps(const std::string& key) {
  std::vector<std::pair<std::string, MapReader>> out;
  auto n = Get(key);
  if (!n) return out;
  if (!n.IsMap()) Fail(key, "expected a map of named entries, got " + Show(n));
  for (const auto& kv : n) {
    const std::string name = kv.first.as<std::string>();
    out.emplace_back(name, MapReader(kv.second, file_, KeyPath(key) + "." + name));
  }
  return out;
}

std::vector<std::string> MapReader::Keys() const {
  std::vector<std::string> keys;
  for (const auto& kv : node_) keys.push_back(kv.first.Scalar());
  return keys;
}

void MapReader::Finish() const {
  for (const auto& kv : node_) {
    const std::string k = kv.first.IsScalar() ? kv.first.Scalar() : "?";
    if (!known_.count(k)) {
      std::string allowed;
      for (const auto& a : known_) allowed += (allowed.empty() ? "" : ", ") + a;
      throw ConfigError(file_ + ": key '" + KeyPath(k) +
                        "' is not a known setting (expected one of: " + allowed + ")");
    }
  }
}

}  // namespace dualgrid::scenario
