#include "dualgrid/core/input_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <vector>

namespace dualgrid {
namespace {

std::string KindOf(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISCHR(mode) || S_ISBLK(mode)) return "a device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

}  // namespace

void ReadInputChunks(const std::filesystem::path& path, const std::string& what,
                     const std::function<void(std::string_view)>& chunk, std::uint64_t max_bytes) {
  const auto fail = [&](const std::string& why) {
    throw std::invalid_argument(path.string() + ": " + what + " " + why);
  };
  // O_NONBLOCK: opening a FIFO must not wait for a writer; the type is checked on the open
  // descriptor, so nothing can be swapped in between.
  const int fd = open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0)
    fail(errno == ENOENT ? "not found" : std::string("cannot be read: ") + std::strerror(errno));
  struct stat st {};
  if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    const std::string kind = KindOf(st.st_mode);
    close(fd);
    fail("is " + kind + ", expected a regular file");
  }
  gzFile gz = gzdopen(fd, "rb");  // reads plain files as they are
  if (gz == nullptr) {
    close(fd);
    fail("cannot be read (out of memory)");
  }
  std::vector<char> buffer(1 << 16);
  std::uint64_t total = 0;
  try {
    for (;;) {
      const int n = gzread(gz, buffer.data(), static_cast<unsigned>(buffer.size()));
      if (n < 0) {
        int code = 0;
        const char* msg = gzerror(gz, &code);
        fail(std::string("cannot be read (damaged gzip data: ") + (msg ? msg : "?") + ")");
      }
      if (n == 0) break;
      total += static_cast<std::uint64_t>(n);
      if (total > max_bytes)
        fail("is larger than " + std::to_string(max_bytes >> 20) +
             " MiB (the cap for text inputs; compressed files count as decompressed)");
      chunk(std::string_view(buffer.data(), static_cast<std::size_t>(n)));
    }
  } catch (...) {
    gzclose(gz);
    throw;
  }
  gzclose(gz);
}

std::string ReadInputText(const std::filesystem::path& path, const std::string& what,
                          std::uint64_t max_bytes) {
  std::string text;
  ReadInputChunks(
      path, what, [&](std::string_view c) { text.append(c); }, max_bytes);
  return text;
}

}  // namespace dualgrid
