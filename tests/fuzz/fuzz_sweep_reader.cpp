// libFuzzer target for the files a sweep and collect read back (outputs/src/read_results.cpp on
// the checked reader): the input is read as a sweep plan (plan.json), as a result table
// (table.json) and as a run's summary.json. Each must either be read or be refused with a
// std::invalid_argument (one line naming the file and the key). Any other exception, a crash, a
// hang, or a sanitizer report is a bug; each one found becomes a case in tests/hostile/.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "dualgrid/outputs/read_results.hpp"

namespace {

std::filesystem::path RunDir() {
  static const std::filesystem::path dir = [] {
    std::string tmpl = (std::filesystem::temp_directory_path() / "fuzz_sweep.XXXXXX").string();
    if (mkdtemp(tmpl.data()) == nullptr) std::abort();
    return std::filesystem::path(tmpl);
  }();
  return dir;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  using namespace dualgrid::outputs;
  try {
    const SweepPlan plan = ParseSweepPlan(ParseJsonText(text, "plan.json"));
    (void)SweepPlanJson(plan);
    for (const auto& r : plan.runs) (void)RunFolder("/sweep", r.setting, r.seed);
  } catch (const std::invalid_argument&) {
  }
  try {
    (void)ParseTableJson(ParseJsonText(text, "table.json"));
  } catch (const std::invalid_argument&) {
  }
  // summary.json through the file reader (ReadRunState never throws: an unreadable summary is a
  // run that did not finish).
  {
    std::ofstream out(RunDir() / "summary.json", std::ios::binary | std::ios::trunc);
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    if (!out) std::abort();
  }
  (void)ReadRunState(RunDir());
  return 0;
}
