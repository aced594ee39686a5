// Reading the files users give us: once, streaming, bounded. Every input is untrusted: only
// regular files are opened (a FIFO would block, a device never end, a directory is a mistake),
// gzip is decompressed transparently, and no input is read past a documented size.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>

namespace dualgrid {

/// Largest streamed input [bytes], counted after decompression (SUMO networks, route and
/// additional files, recordings): above a city's network (hundreds of MB) and low enough that
/// an endless input ends within seconds.
inline constexpr std::uint64_t kMaxStreamedInputBytes = std::uint64_t{1} << 30;
/// Largest input read whole into memory [bytes] (scenario and suite YAML, JSON written by
/// dualgrid): far above any real one.
inline constexpr std::uint64_t kMaxTextInputBytes = std::uint64_t{64} << 20;

/// Reads `path` from start to end in chunks passed to `chunk` (each valid during the call only),
/// decompressing gzip by content, whatever the name. Refuses at once, before reading, what is not
/// a regular file. Throws std::invalid_argument "<path>: <what> <why>" for a missing, unreadable
/// or non-regular file, damaged gzip data, or more than `max_bytes`; `what` names the input
/// ("SUMO route file"). Exceptions thrown by `chunk` propagate.
void ReadInputChunks(const std::filesystem::path& path, const std::string& what,
                     const std::function<void(std::string_view)>& chunk,
                     std::uint64_t max_bytes = kMaxStreamedInputBytes);

/// The whole (decompressed) content of `path`, through ReadInputChunks with `max_bytes`.
std::string ReadInputText(const std::filesystem::path& path, const std::string& what,
                          std::uint64_t max_bytes = kMaxTextInputBytes);

}  // namespace dualgrid
