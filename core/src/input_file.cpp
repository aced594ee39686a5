#include "dualgrid/core/input_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace dualgrid {
namespace {

const volatile std::sig_atomic_t* g_stop_flag = nullptr;

constexpr std::size_t kChunk = std::size_t{1} << 16;
// Reads shorter than this finish whatever the stop flag says (a stopped `experiment` still reads
// its finished seeds' small files to write its summary); longer ones end at the signal.
constexpr std::uint64_t kStopCheckAfter = std::uint64_t{16} << 20;

std::string KindOf(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISCHR(mode) || S_ISBLK(mode)) return "a device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

std::string Mebibytes(std::uint64_t bytes) {
  return bytes >= (std::uint64_t{1} << 20) ? std::to_string(bytes >> 20) + " MiB"
                                           : std::to_string(bytes) + " bytes";
}

// Why `path` cannot be stat'ed, in words: a loop and a dangling link are told apart from a
// missing file (lstat still sees the link).
std::string WhyMissing(const std::filesystem::path& path, int err) {
  if (err == ELOOP) return "is a symbolic link loop (too many levels of symbolic links)";
  if (err == ENOENT) {
    struct stat lst {};
    if (lstat(path.c_str(), &lst) == 0 && S_ISLNK(lst.st_mode))
      return "is a dangling symbolic link (its target does not exist)";
    return "not found";
  }
  if (err == ENOTDIR) return "not found (a part of its path is not a folder)";
  if (err == ENAMETOOLONG) return "cannot be read: its name is too long";
  return std::string("cannot be read: ") + std::strerror(err);
}

// stat() of `path`, failing with the reason named.
struct stat StatInput(const std::filesystem::path& path, const std::string& what) {
  struct stat st {};
  if (stat(path.c_str(), &st) != 0) FailInput(path, what, WhyMissing(path, errno));
  return st;
}

}  // namespace

void SetInputStopFlag(const volatile std::sig_atomic_t* flag) { g_stop_flag = flag; }

void FailInput(const std::filesystem::path& path, const std::string& what, const std::string& why) {
  throw std::invalid_argument(path.string() + ": " + what + " " + why);
}

std::uint64_t CheckInputFile(const std::filesystem::path& path, const std::string& what) {
  const struct stat st = StatInput(path, what);
  if (!S_ISREG(st.st_mode))
    FailInput(path, what, "is " + KindOf(st.st_mode) + ", expected a regular file");
  if (access(path.c_str(), R_OK) != 0)
    FailInput(path, what, std::string("cannot be read: ") + std::strerror(errno));
  return static_cast<std::uint64_t>(st.st_size);
}

void CheckInputFolder(const std::filesystem::path& path, const std::string& what) {
  const struct stat st = StatInput(path, what);
  if (!S_ISDIR(st.st_mode))
    FailInput(path, what, "is " + KindOf(st.st_mode) + ", expected a folder");
  if (access(path.c_str(), R_OK | X_OK) != 0)
    FailInput(path, what, std::string("cannot be read: ") + std::strerror(errno));
}

bool InputExists(const std::filesystem::path& path) {
  struct stat lst {};
  return lstat(path.c_str(), &lst) == 0;
}

InputStream::InputStream(const std::filesystem::path& path, std::string what,
                         std::uint64_t max_bytes)
    : path_(path), what_(std::move(what)), max_bytes_(max_bytes) {
  // O_NONBLOCK: opening a FIFO must not wait for a writer; the type is checked on the open
  // descriptor, so nothing can be swapped in between.
  const int fd = open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) Fail(WhyMissing(path, errno));
  struct stat st {};
  if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    const std::string kind = KindOf(st.st_mode);
    close(fd);
    Fail("is " + kind + ", expected a regular file");
  }
  gz_ = gzdopen(fd, "rb");  // reads plain files as they are
  if (gz_ == nullptr) {
    close(fd);
    Fail("cannot be read (out of memory)");
  }
}

InputStream::~InputStream() {
  if (gz_ != nullptr) gzclose(gz_);
}

void InputStream::Fail(const std::string& why) const { FailInput(path_, what_, why); }

std::size_t InputStream::Fill() {
  if (end_) return 0;
  if (g_stop_flag != nullptr && *g_stop_flag != 0 && total_ >= kStopCheckAfter)
    throw InputStopped(path_.string() + ": reading stopped by signal " +
                       std::to_string(static_cast<int>(*g_stop_flag)));
  buffer_.erase(0, pos_);
  pos_ = 0;
  const std::size_t old = buffer_.size();
  buffer_.resize(old + kChunk);
  const int n = gzread(gz_, buffer_.data() + old, static_cast<unsigned>(kChunk));
  int code = Z_OK;
  const char* msg = gzerror(gz_, &code);
  // A truncated stream ends with Z_BUF_ERROR ("unexpected end of file"), not with n < 0.
  if (n < 0 || (code != Z_OK && code != Z_STREAM_END))
    Fail(std::string("cannot be read (damaged gzip data: ") + (msg ? msg : "?") + ")");
  buffer_.resize(old + static_cast<std::size_t>(n));
  if (n == 0) end_ = true;
  total_ += static_cast<std::uint64_t>(n);
  if (total_ > max_bytes_)
    Fail("is larger than " + Mebibytes(max_bytes_) +
         " (the cap for this input; compressed files count as decompressed)");
  return static_cast<std::size_t>(n);
}

std::size_t InputStream::Read(char* buffer, std::size_t n) {
  if (pos_ == buffer_.size() && Fill() == 0) return 0;
  const std::size_t k = std::min(n, buffer_.size() - pos_);
  std::memcpy(buffer, buffer_.data() + pos_, k);
  pos_ += k;
  return k;
}

std::size_t InputStream::ReadExactly(char* buffer, std::size_t n) {
  std::size_t done = 0;
  while (done < n) {
    const std::size_t k = Read(buffer + done, n - done);
    if (k == 0) break;
    done += k;
  }
  return done;
}

bool InputStream::ReadLine(std::string* line, std::uint64_t max_line) {
  std::size_t scanned = pos_;
  for (;;) {
    const std::size_t nl = buffer_.find('\n', scanned);
    if (nl != std::string::npos) {
      line->assign(buffer_, pos_, nl - pos_);
      pos_ = nl + 1;
      break;
    }
    if (buffer_.size() - pos_ > max_line)
      Fail("has a line longer than " + Mebibytes(max_line) + " (the cap for one line)");
    scanned = buffer_.size() - pos_;  // Fill() moves the unread bytes to the front
    if (Fill() == 0) {
      if (pos_ == buffer_.size()) return false;
      line->assign(buffer_, pos_, std::string::npos);
      pos_ = buffer_.size();
      break;
    }
  }
  if (line->size() > max_line)
    Fail("has a line longer than " + Mebibytes(max_line) + " (the cap for one line)");
  if (!line->empty() && line->back() == '\r') line->pop_back();
  return true;
}

void ReadInputChunks(const std::filesystem::path& path, const std::string& what,
                     const std::function<void(std::string_view)>& chunk, std::uint64_t max_bytes) {
  InputStream in(path, what, max_bytes);
  std::string buffer(kChunk, '\0');
  for (;;) {
    const std::size_t n = in.Read(buffer.data(), buffer.size());
    if (n == 0) break;
    chunk(std::string_view(buffer.data(), n));
  }
}

std::string ReadInputText(const std::filesystem::path& path, const std::string& what,
                          std::uint64_t max_bytes) {
  std::string text;
  ReadInputChunks(
      path, what, [&](std::string_view c) { text.append(c); }, max_bytes);
  return text;
}

}  // namespace dualgrid
