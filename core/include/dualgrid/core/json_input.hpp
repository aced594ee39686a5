// JSON from files users give us (RadarScenes' scenes.json and sensors.json, nuScenes tables,
// dualgrid's own files read back): bounded like every input (core/input_file.hpp), nested at most
// 64 deep, and a key given twice in one object refused (a parser keeping the last silently drops
// data). Errors are std::invalid_argument of one line naming the file; no library text.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "dualgrid/core/input_file.hpp"

namespace dualgrid {

/// Deepest nesting of lists and objects accepted (a million [ would exhaust the stack).
inline constexpr int kMaxJsonDepth = 64;

/// Parses `text`, the content of `file` (named in errors). Throws std::invalid_argument
/// "<file>: not valid JSON (at byte N of M; truncated or damaged?)", "<file>: key 'a.b' given
/// twice" or "<file>: lists or objects nested more than 64 deep".
nlohmann::json ParseJsonInput(const std::string& text, const std::string& file);

/// The same for the file `path`, parsed as it is read through InputStream (regular files only,
/// at most `max_bytes`, `what` naming its role): a file that is not JSON is refused at its first
/// bytes. std::bad_alloc is reported naming the file.
nlohmann::json ReadJsonInput(const std::filesystem::path& path, const std::string& what,
                             std::uint64_t max_bytes = kMaxTextInputBytes);

/// NamingInputOnFailure for a reader of JSON: also a nlohmann::json::exception that a reader's
/// own checks missed (a value of another type) becomes std::invalid_argument "<path>: <what>
/// holds a value of an unexpected type (<library text>)", never an internal error.
template <class Read>
auto ReadingJsonInput(const std::filesystem::path& path, const std::string& what, Read&& read)
    -> decltype(read()) {
  try {
    return NamingInputOnFailure(path, what, std::forward<Read>(read));
  } catch (const nlohmann::json::exception& e) {
    FailInput(path, what, std::string("holds a value of an unexpected type (") + e.what() + ")");
  }
}

}  // namespace dualgrid
