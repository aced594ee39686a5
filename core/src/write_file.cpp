#include "dualgrid/core/write_file.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace dualgrid {

std::string SystemReason() { return errno ? std::strerror(errno) : "unknown error"; }

void WriteFileChecked(const std::filesystem::path& path,
                      std::initializer_list<std::string_view> parts) {
  auto fail = [&] {
    throw std::runtime_error("cannot write " + path.string() + ": " + SystemReason());
  };
  errno = 0;
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) fail();
  bool ok = true;
  for (std::string_view p : parts) ok = ok && std::fwrite(p.data(), 1, p.size(), f) == p.size();
  ok = ok && std::fflush(f) == 0;
  const int saved = errno;
  const bool closed = std::fclose(f) == 0;
  if (!ok) errno = saved;
  if (!ok || !closed) fail();
}

}  // namespace dualgrid
