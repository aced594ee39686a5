// libFuzzer target for the replay reader (outputs/src/recording.cpp on the checked reader,
// outputs/src/read_back.cpp): the input is a recording, index.json and frames.bin separated by the
// line "@@frames.bin@@". Every input must either be read (header, then every frame decoded) or be
// refused with a std::invalid_argument (one line naming the file and the key). Any other
// exception, a crash, a hang, or a sanitizer report is a bug; each one found becomes a case in
// tests/hostile/.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <string_view>

#include "dualgrid/outputs/recording.hpp"

namespace {

std::filesystem::path RunDir() {
  static const std::filesystem::path dir = [] {
    std::string tmpl = (std::filesystem::temp_directory_path() / "fuzz_replay.XXXXXX").string();
    if (mkdtemp(tmpl.data()) == nullptr) std::abort();
    std::filesystem::create_directories(std::filesystem::path(tmpl) / "replay");
    return std::filesystem::path(tmpl);
  }();
  return dir;
}

void Write(const std::filesystem::path& path, std::string_view bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  constexpr std::string_view kSeparator = "\n@@frames.bin@@\n";
  const std::size_t at = input.find(kSeparator);
  const std::filesystem::path dir = RunDir();
  Write(dir / "replay" / "index.json", input.substr(0, at));
  Write(dir / "replay" / "frames.bin",
        at == std::string_view::npos ? std::string_view() : input.substr(at + kSeparator.size()));
  try {
    const dualgrid::outputs::replay::Reader reader(dir);
    const auto& h = reader.header();
    // The reader admits frames of up to 1 GiB (its documented bound); decoding such a frame is
    // allowed, but not useful to a fuzzer with a 2 GB memory limit.
    const double frame_bytes =
        (7.0 * h.cells_x * h.cells_y + 4.0 * h.max_particles) * static_cast<double>(h.modes.size());
    if (frame_bytes > 64e6) return 0;
    for (std::size_t i = 0; i < reader.size() && i < 8; ++i) (void)reader.Load(i);
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
