// libFuzzer target for the scenario loader: any text must either load or be refused with a
// scenario::ConfigError (one line naming the file and the key). Any other exception, a crash, a
// hang, or a sanitizer report is a bug; each one found becomes a case in tests/hostile/.
#include <cstddef>
#include <cstdint>
#include <string>

#include "dualgrid/scenario/loader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    dualgrid::scenario::LoadScenarioText(text, "fuzz.yaml");
  } catch (const dualgrid::scenario::ConfigError&) {
  }
  return 0;
}
