// Text files written whole or as they go, every write checked (docs/reliability.md), and the
// temporary folders of a run's working files.
#pragma once

#include <cstdio>
#include <filesystem>
#include <string>

namespace dualgrid::outputs {

/// A text output written as it goes: plain, or gzip-compressed when the path ends in ".gz".
/// Every write is checked when the file is closed: Close() throws std::runtime_error naming the
/// file and the system's reason (a full disk, a file-size limit), so a failed write is never
/// silent. Not copyable; the destructor closes without throwing (use Close() for the check).
class OutputFile {
 public:
  explicit OutputFile(const std::filesystem::path& path);
  ~OutputFile();
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  /// Appends to an in-memory buffer, written out in large blocks.
  std::string& buffer() { return buffer_; }
  /// Writes the buffer out when it is large (call once per step).
  void MaybeFlush();
  void Close();
  const std::filesystem::path& path() const { return path_; }

 private:
  void Flush();
  [[noreturn]] void Fail(const std::string& what);

  std::filesystem::path path_;
  std::string buffer_;
  std::FILE* file_ = nullptr;
  void* gz_ = nullptr;  // gzFile
};

/// Writes a whole text file, checked: throws std::runtime_error naming the file and the reason.
void WriteTextFile(const std::filesystem::path& path, const std::string& text);

/// A new, empty temporary folder (under $TMPDIR or /tmp), removed with everything in it when
/// destroyed, unless destroyed while an exception is propagating: then it is kept for the
/// working files an error message may name (e.g. SUMO's log).
class TempDir {
 public:
  explicit TempDir(const std::string& purpose);
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
  int exceptions_ = 0;
};

}  // namespace dualgrid::outputs
