// libFuzzer target for the regression-suite reader (scenario::LoadSuite): the input is written as
// a suite file two folders below a copy-free view of the repository's scenarios (a symlink), so
// that the seed corpus's `scenario: ../../scenarios/X.yaml` resolves. Every input must either
// load or be refused with a scenario::ConfigError (one line naming the file and the key). Any
// other exception, a crash, a hang, or a sanitizer report is a bug; each one found becomes a case
// in tests/hostile/.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "dualgrid/scenario/suite.hpp"

namespace {

std::filesystem::path SuiteFile() {
  static const std::filesystem::path file = [] {
    std::string tmpl = (std::filesystem::temp_directory_path() / "fuzz_suite.XXXXXX").string();
    if (mkdtemp(tmpl.data()) == nullptr) std::abort();
    const std::filesystem::path root(tmpl);
    std::filesystem::create_directory_symlink(DUALGRID_SOURCE_DIR "/scenarios", root / "scenarios");
    std::filesystem::create_directories(root / "tests" / "regression");
    return root / "tests" / "regression" / "suite.yaml";
  }();
  return file;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  {
    std::ofstream out(SuiteFile(), std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    if (!out) std::abort();
  }
  try {
    (void)dualgrid::scenario::LoadSuite(SuiteFile());
  } catch (const dualgrid::scenario::ConfigError&) {
  }
  return 0;
}
