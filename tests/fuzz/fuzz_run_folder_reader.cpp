// libFuzzer target for the run-folder reader (recorded/src/run_folder.cpp): the input is
// scans.csv, detections.csv and ground_truth.csv joined by lines "@@@". Every input must be read
// (then its key frames) or refused with std::invalid_argument; any other exception, a crash, a
// hang or a sanitizer report is a bug.
#include <cstddef>
#include <cstdint>
#include <stdexcept>

#include "dualgrid/recorded/run_folder.hpp"
#include "fuzz_files.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  dualgrid::fuzz::WriteParts(input, {"scans.csv", "detections.csv", "ground_truth.csv"});
  try {
    const auto seq = dualgrid::recorded::ReadRunFolder(dualgrid::fuzz::Folder());
    (void)dualgrid::recorded::ReadKeyFrames(dualgrid::fuzz::Folder(), seq, 0.5);
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
