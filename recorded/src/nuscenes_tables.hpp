// The JSON tables of a nuScenes version folder (docs/schema_nuscenes.md of the public devkit),
// loaded on demand and indexed by token, with checked access: every problem is one
// std::invalid_argument naming the file, the record's token and the field.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <unordered_map>
#include <vector>

#include <nlohmann/json.hpp>

#include "dualgrid/core/types.hpp"

namespace dualgrid::recorded::nuscenes {

using Json = nlohmann::json;

/// One table: its file, its records and an index token -> record.
struct Table {
  std::filesystem::path file;
  const Json* records = nullptr;
  std::unordered_map<std::string, std::size_t> index;
};

class Tables {
 public:
  /// `dir`: the version folder (ROOT/v1.0-mini).
  explicit Tables(std::filesystem::path dir) : dir_(std::move(dir)) {}

  /// The table `name` (NAME.json), loaded once. Throws when it is missing, not JSON, not an
  /// array of objects with string tokens, or holds a token twice.
  const Table& Get(const std::string& name);
  /// The record of `token` in table `name`; `from` names the referring file, record and field
  /// for the error when the token points nowhere.
  const Json& Record(const std::string& name, const std::string& token, const std::string& from);

  const std::filesystem::path& dir() const { return dir_; }

 private:
  std::filesystem::path dir_;
  std::map<std::string, Json> json_;
  std::map<std::string, Table> tables_;
};

/// Checked fields of a record of `table` (errors name table's file, the record's token and
/// the key).
std::string Str(const Table& table, const Json& record, const std::string& key);
std::int64_t Int(const Table& table, const Json& record, const std::string& key);
bool Bool(const Table& table, const Json& record, const std::string& key);
/// `n` finite numbers (translation 3, rotation 4, size 3).
std::vector<double> Numbers(const Table& table, const Json& record, const std::string& key,
                            std::size_t n);
/// "FILE: record 'TOKEN', field 'KEY': " for error messages.
std::string Where(const Table& table, const Json& record, const std::string& key);

/// The heading [rad] about z of a unit quaternion w, x, y, z (its yaw).
double QuaternionYaw(const std::vector<double>& wxyz);
/// Rotates `v` (3) by the unit quaternion w, x, y, z.
std::vector<double> Rotate(const std::vector<double>& wxyz, const std::vector<double>& v);

}  // namespace dualgrid::recorded::nuscenes
