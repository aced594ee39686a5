// Private helpers: std::optional<double> <-> JSON null.
#pragma once

#include <optional>
#include <string>

#include <nlohmann/json.hpp>

namespace dualgrid::eval::detail {

inline nlohmann::json OptToJson(const std::optional<double>& v) {
  return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
}

inline std::optional<double> OptFromJson(const nlohmann::json& j, const std::string& key) {
  const auto it = j.find(key);
  if (it == j.end() || it->is_null()) return std::nullopt;
  return it->get<double>();
}

}  // namespace dualgrid::eval::detail
