// Writing whole files, every call checked, failures reported with the system's reason
// (docs/reliability.md, "Outputs cannot lie"): for the writers below outputs/ (recorded data
// sets, SUMO's route file), which cannot use outputs::OutputFile.
#pragma once

#include <filesystem>
#include <initializer_list>
#include <string>
#include <string_view>

namespace dualgrid {

/// The system's reason for the last failed call: strerror(errno) ("No space left on device",
/// "File too large"), or "unknown error" when errno is 0.
std::string SystemReason();

/// Writes `parts` one after another to `path` (created or truncated). Throws std::runtime_error
/// "cannot write PATH: REASON" when opening, a write or closing fails.
void WriteFileChecked(const std::filesystem::path& path,
                      std::initializer_list<std::string_view> parts);

}  // namespace dualgrid
