// Reading back what dualgrid wrote (a sweep's plan.json, a run's table.json, summary.json and
// metrics.json, a recording's index.json): one checked reader for all of them. Such files are
// untrusted like any input (copied, truncated, edited by hand, written by another release), so
// they are read bounded (core/input_file.hpp: regular files only, a size cap) and every access
// names the file, the key and what was expected. No library text (nlohmann, std::filesystem)
// reaches a user: every failure is a std::invalid_argument of one line,
//   "<file>: key '<key>': expected <what>, found <what was there>".
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace dualgrid::outputs {

/// A value inside a read-back JSON document, with the file and the key path that lead to it.
/// Borrows the document (JsonFile keeps it alive); copies are cheap enough for the non-hot paths
/// that read back files.
class JsonAt {
 public:
  JsonAt(const nlohmann::json& value, std::shared_ptr<const std::string> file, std::string key)
      : value_(&value), file_(std::move(file)), key_(std::move(key)) {}

  /// Throws std::invalid_argument "<file>: key '<key>': expected <expected>, found <kind>".
  [[noreturn]] void Fail(const std::string& expected) const;

  bool IsNull() const { return value_->is_null(); }
  /// This is an object with the member `name`.
  bool Has(const std::string& name) const;
  /// The member `name` of this object (which must be one); fails naming `name` when missing.
  JsonAt operator[](const std::string& name) const;
  /// The member `name`, or std::nullopt when it is absent or null.
  std::optional<JsonAt> Find(const std::string& name) const;
  /// The elements of this array (which must be one), at most `max` of them.
  std::vector<JsonAt> Items(std::size_t max = 100000000) const;
  /// Element i of this array (which must be one and have more than i elements).
  JsonAt Item(std::size_t i) const;
  /// The elements of this array, which must have exactly `n`.
  std::vector<JsonAt> Tuple(std::size_t n) const;
  /// The members of this object (which must be one), in the document's order.
  std::vector<std::pair<std::string, JsonAt>> Members() const;

  /// A finite number in [lo, hi].
  double Number(double lo = -1e300, double hi = 1e300) const;
  /// A finite number, or std::nullopt for null (an undefined metric).
  std::optional<double> NumberOrNull() const;
  /// A whole number in [lo, hi] (written as an integer).
  std::int64_t Integer(std::int64_t lo, std::int64_t hi) const;
  std::uint64_t Unsigned(std::uint64_t hi = UINT64_MAX) const;
  std::string Text() const;
  bool Flag() const;

  const nlohmann::json& raw() const { return *value_; }
  const std::string& file() const { return *file_; }
  const std::string& key() const { return key_; }

 private:
  const nlohmann::json* value_;
  std::shared_ptr<const std::string> file_;
  std::string key_;  ///< "a.b[3].c"; "" for the document itself
};

/// A parsed document and the name of the file it came from.
class JsonFile {
 public:
  JsonFile(nlohmann::json doc, std::string file);
  JsonAt Root() const { return JsonAt(*doc_, file_, ""); }
  const nlohmann::json& doc() const { return *doc_; }

 private:
  std::shared_ptr<const nlohmann::json> doc_;
  std::shared_ptr<const std::string> file_;
};

/// Parses `text` as the content of `file` (named in errors). Throws std::invalid_argument
/// "<file>: not valid JSON (at byte N; truncated or damaged?)".
JsonFile ParseJsonText(const std::string& text, const std::string& file);

/// Reads `path` through the bounded reader (regular files only, at most `max_bytes`) and parses
/// it; `what` names the file's role in errors ("sweep plan"). Throws std::invalid_argument.
JsonFile ReadJsonFile(const std::filesystem::path& path, const std::string& what,
                      std::uint64_t max_bytes = std::uint64_t{64} << 20);

}  // namespace dualgrid::outputs
