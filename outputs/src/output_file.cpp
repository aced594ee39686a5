#include "dualgrid/outputs/output_file.hpp"

#include <stdlib.h>
#include <zlib.h>

#include <cerrno>
#include <cstring>
#include <exception>
#include <stdexcept>

#include "dualgrid/core/write_file.hpp"

namespace dualgrid::outputs {

namespace {
constexpr std::size_t kFlushBytes = 1 << 20;
}  // namespace

OutputFile::OutputFile(const std::filesystem::path& path) : path_(path) {
  errno = 0;
  if (path.extension() == ".gz") {
    gz_ = gzopen(path.c_str(), "wb6");
    if (!gz_) Fail("cannot create");
  } else {
    file_ = std::fopen(path.c_str(), "wb");
    if (!file_) Fail("cannot create");
  }
  buffer_.reserve(kFlushBytes + (kFlushBytes >> 2));
}

OutputFile::~OutputFile() {
  if (file_) std::fclose(file_);
  if (gz_) gzclose(static_cast<gzFile>(gz_));
}

void OutputFile::Fail(const std::string& what) {
  throw std::runtime_error(what + " " + path_.string() + ": " + SystemReason());
}

void OutputFile::MaybeFlush() {
  if (buffer_.size() >= kFlushBytes) Flush();
}

void OutputFile::Flush() {
  if (buffer_.empty()) return;
  errno = 0;
  if (file_) {
    if (std::fwrite(buffer_.data(), 1, buffer_.size(), file_) != buffer_.size())
      Fail("cannot write");
  } else if (gz_) {
    if (gzwrite(static_cast<gzFile>(gz_), buffer_.data(), static_cast<unsigned>(buffer_.size())) !=
        static_cast<int>(buffer_.size()))
      Fail("cannot write");
  }
  buffer_.clear();
}

void OutputFile::Close() {
  Flush();
  errno = 0;
  if (file_) {
    const bool ok = std::fflush(file_) == 0 && std::ferror(file_) == 0;
    const int rc = std::fclose(file_);
    file_ = nullptr;
    if (!ok || rc != 0) Fail("cannot write");
  }
  if (gz_) {
    const int rc = gzclose(static_cast<gzFile>(gz_));
    gz_ = nullptr;
    if (rc != Z_OK) Fail("cannot write");
  }
}

TempDir::TempDir(const std::string& purpose) : exceptions_(std::uncaught_exceptions()) {
  std::string pattern =
      (std::filesystem::temp_directory_path() / ("dualgrid_" + purpose + "_XXXXXX")).string();
  if (!mkdtemp(pattern.data()))
    throw std::runtime_error("cannot create a temporary folder " + pattern + ": " + SystemReason());
  path_ = pattern;
}

TempDir::~TempDir() {
  if (std::uncaught_exceptions() > exceptions_) return;
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

void WriteTextFile(const std::filesystem::path& path, const std::string& text) {
  OutputFile out(path);
  out.buffer() = text;
  out.Close();
}

}  // namespace dualgrid::outputs
