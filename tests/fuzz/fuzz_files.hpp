// Shared by the fuzz targets of readers that take a folder of files: the fuzzer's input is split
// into named files at separator lines "@@<name>@@", written into one temporary folder per
// process (a fresh copy of each file every input; files the input does not name are removed).
#pragma once

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

namespace dualgrid::fuzz {

/// The process's temporary folder (created once).
inline const std::filesystem::path& Folder() {
  static const std::filesystem::path dir = [] {
    std::string tmpl = (std::filesystem::temp_directory_path() / "fuzz_files.XXXXXX").string();
    if (mkdtemp(tmpl.data()) == nullptr) std::abort();
    return std::filesystem::path(tmpl);
  }();
  return dir;
}

inline void WriteFile(const std::filesystem::path& path, std::string_view bytes) {
  std::filesystem::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) std::abort();
}

/// Writes the parts of `input` as the files `names` (relative to Folder()) in order: the text
/// before the first "\n@@@\n" is names[0], and so on; names with no part are removed.
inline void WriteParts(std::string_view input, const std::vector<std::string>& names) {
  constexpr std::string_view kSeparator = "\n@@@\n";
  for (const std::string& name : names) {
    const std::filesystem::path path = Folder() / name;
    if (input.data() == nullptr) {
      std::error_code ec;
      std::filesystem::remove(path, ec);
      continue;
    }
    const std::size_t at = input.find(kSeparator);
    WriteFile(path, input.substr(0, at));
    input =
        at == std::string_view::npos ? std::string_view() : input.substr(at + kSeparator.size());
  }
}

}  // namespace dualgrid::fuzz
