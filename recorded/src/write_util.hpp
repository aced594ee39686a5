// What the dataset writers share: checked JSON files and deterministic hex ids.
#pragma once

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "dualgrid/core/write_file.hpp"

namespace dualgrid::recorded {

/// Writes `j` (indented by `indent`, -1: one line) to `file`; throws std::runtime_error naming
/// the file and the system's reason when the write fails.
inline void WriteJson(const std::filesystem::path& file, const nlohmann::json& j, int indent = 1) {
  WriteFileChecked(file, {j.dump(indent), "\n"});
}

/// A deterministic 32-hex-digit id of `name` and `index` (FNV-1a 64, two seeds).
inline std::string HexId(const std::string& name, std::size_t index) {
  auto fnv = [&](std::uint64_t h) {
    for (char c : name + "#" + std::to_string(index))
      h = (h ^ static_cast<unsigned char>(c)) * 1099511628211ull;
    return h;
  };
  char buf[33];
  std::snprintf(buf, sizeof buf, "%016llx%016llx",
                static_cast<unsigned long long>(fnv(14695981039346656037ull)),
                static_cast<unsigned long long>(fnv(0x9e3779b97f4a7c15ull)));
  return buf;
}

}  // namespace dualgrid::recorded
