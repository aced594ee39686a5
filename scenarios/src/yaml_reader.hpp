// A thin reader over yaml-cpp that remembers where it is, so every error names the file, the key
// path and what was expected, and that rejects keys it was not asked for (typos are errors, not
// silently ignored settings).
#pragma once

#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "dualgrid/core/types.hpp"
#include "dualgrid/scenario/loader.hpp"

namespace dualgrid::scenario {

class MapReader {
 public:
  MapReader(YAML::Node node, std::string file, std::string path);

  /// True if the key is present (marks it as known).
  bool Has(const std::string& key);
  /// True if the key is present and holds a map (marks it as known).
  bool IsMap(const std::string& key);
  /// Reads `key` into `*out` if present; leaves the default otherwise.
  void Read(const std::string& key, double* out);
  void Read(const std::string& key, int* out);
  void Read(const std::string& key, std::uint64_t* out);
  void Read(const std::string& key, bool* out);
  void Read(const std::string& key, std::string* out);
  void Read(const std::string& key, std::optional<double>* out);
  void Read(const std::string& key, std::optional<int>* out);
  void Read(const std::string& key, Position* out);
  void Read(const std::string& key, std::vector<Position>* out);
  void Read(const std::string& key, std::vector<std::string>* out);
  void Read(const std::string& key, std::vector<double>* out);
  /// Reads an angle given in degrees into radians.
  void ReadDegrees(const std::string& key, double* out_rad);
  /// Reads `key`, which must be present.
  template <typename T>
  void Require(const std::string& key, T* out) {
    if (!Has(key)) Fail(key, "is required");
    Read(key, out);
  }
  /// A nested map (must be a map if present).
  std::optional<MapReader> Map(const std::string& key);
  /// A nested sequence of maps.
  std::vector<MapReader> MapList(const std::string& key);
  /// The keys of a nested map whose values are maps, with their readers (for named entries).
  std::vector<std::pair<std::string, MapReader>> NamedMaps(const std::string& key);
  /// All keys of this map, in file order.
  std::vector<std::string> Keys() const;
  /// Throws if the map holds keys that were never asked for.
  void Finish() const;

  [[noreturn]] void Fail(const std::string& key, const std::string& expected) const;
  const std::string& path() const { return path_; }
  const std::string& file() const { return file_; }

 private:
  YAML::Node Get(const std::string& key);
  std::string KeyPath(const std::string& key) const;
  double ToDouble(const YAML::Node& n, const std::string& key) const;

  YAML::Node node_;
  std::string file_;
  std::string path_;
  std::set<std::string> known_;
};

}  // namespace dualgrid::scenario
