// Reading the files users give us: once, streaming, bounded. Every input is untrusted: only
// regular files are opened (a FIFO would block, a device never end, a directory is a mistake),
// gzip is decompressed transparently, and no input is read past a documented size. Every reader
// of a file in dualgrid goes through this header (tests/core/test_input_sources.cpp keeps it so):
// ReadInputChunks / ReadInputText / InputStream for the bytes, CheckInputFile before handing a
// path to a library that opens it itself (HDF5), CheckInputFolder for folders read as a whole.
#pragma once

#include <csignal>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <new>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

struct gzFile_s;  // zlib's stream (gzFile), opaque here

namespace dualgrid {

/// Largest streamed input [bytes], counted after decompression (SUMO networks, route and
/// additional files, recordings): above a city's network (hundreds of MB) and low enough that
/// an endless input ends within seconds.
inline constexpr std::uint64_t kMaxStreamedInputBytes = std::uint64_t{1} << 30;
/// Largest input read whole into memory [bytes] (scenario and suite YAML, JSON written by
/// dualgrid, RadarScenes' scenes.json and sensors.json, nuScenes tables): far above any real one.
inline constexpr std::uint64_t kMaxTextInputBytes = std::uint64_t{64} << 20;
/// Longest line of a line-oriented input [bytes] (CSV rows, PCD header lines): a row of a
/// dualgrid CSV is under 1 KiB.
inline constexpr std::uint64_t kMaxInputLineBytes = std::uint64_t{1} << 20;

/// Reading was stopped by SIGINT/SIGTERM (SetInputStopFlag): not a failure of the input.
class InputStopped : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The flag a signal handler sets (nonzero: stop). Past the first 16 MiB of an input, readers
/// check it every chunk (64 KiB) and throw InputStopped, so that no long or endless read outlives
/// a SIGTERM, while the short reads a stopped command still does (an experiment's finished seeds)
/// complete. `flag` must outlive every read; nullptr (the default) disables the check.
void SetInputStopFlag(const volatile std::sig_atomic_t* flag);

/// Throws std::invalid_argument "<path>: <what> <why>".
[[noreturn]] void FailInput(const std::filesystem::path& path, const std::string& what,
                            const std::string& why);

/// Checks, without opening it, that `path` is a regular file that may be read, and returns its
/// size [bytes]. Throws std::invalid_argument "<path>: <what> ..." naming the reason: not found,
/// a dangling symbolic link, a symbolic link loop, a directory, a FIFO, a device, a socket, or
/// no permission. For readers that hand the path to a library that opens it (HDF5).
std::uint64_t CheckInputFile(const std::filesystem::path& path, const std::string& what);

/// Checks that `path` is a folder that may be listed (same reasons as CheckInputFile).
void CheckInputFolder(const std::filesystem::path& path, const std::string& what);

/// True when `path` names something (a file, folder or any other entry, even a dangling or
/// looping symbolic link): "absent" and "present but unusable" get different messages.
bool InputExists(const std::filesystem::path& path);

/// One input opened for reading: refused before open() can block unless it is a regular file
/// (opened O_NONBLOCK, then its type checked on the descriptor, so nothing can be swapped in
/// between); gzip decompressed by content; at most `max_bytes` (after decompression) delivered.
/// Every error is a std::invalid_argument "<path>: <what> <why>". Not copyable.
class InputStream {
 public:
  InputStream(const std::filesystem::path& path, std::string what,
              std::uint64_t max_bytes = kMaxStreamedInputBytes);
  ~InputStream();
  InputStream(const InputStream&) = delete;
  InputStream& operator=(const InputStream&) = delete;

  /// Up to `n` bytes into `buffer`; 0 at the end. Throws past `max_bytes` or for damaged gzip.
  std::size_t Read(char* buffer, std::size_t n);
  /// The next line without its '\n' (and '\r'); false at the end. Throws for a line longer than
  /// `max_line` [bytes] (the bound is named), so an input without newlines ends early.
  bool ReadLine(std::string* line, std::uint64_t max_line = kMaxInputLineBytes);
  /// Exactly `n` bytes (binary payloads); fewer only at the end of the input.
  std::size_t ReadExactly(char* buffer, std::size_t n);

  const std::filesystem::path& path() const { return path_; }
  /// Bytes delivered so far (after decompression).
  std::uint64_t offset() const { return total_; }
  /// Throws std::invalid_argument "<path>: <what> <why>".
  [[noreturn]] void Fail(const std::string& why) const;

 private:
  std::size_t Fill();

  std::filesystem::path path_;
  std::string what_;
  std::uint64_t max_bytes_;
  std::uint64_t total_ = 0;
  ::gzFile_s* gz_ = nullptr;
  std::string buffer_;  // bytes read but not yet delivered: [pos_, size())
  std::size_t pos_ = 0;
  bool end_ = false;
};

/// Reads `path` from start to end in chunks passed to `chunk` (each valid during the call only),
/// through InputStream. Exceptions thrown by `chunk` propagate.
void ReadInputChunks(const std::filesystem::path& path, const std::string& what,
                     const std::function<void(std::string_view)>& chunk,
                     std::uint64_t max_bytes = kMaxStreamedInputBytes);

/// The whole (decompressed) content of `path`, through ReadInputChunks with `max_bytes`.
std::string ReadInputText(const std::filesystem::path& path, const std::string& what,
                          std::uint64_t max_bytes = kMaxTextInputBytes);

/// `read()`, with std::bad_alloc turned into std::invalid_argument "<path>: <what> is too large
/// to read (out of memory; the limits of each input: docs/reliability.md)": a reader whose
/// allocation fails names its file.
template <class Read>
auto NamingInputOnFailure(const std::filesystem::path& path, const std::string& what, Read&& read)
    -> decltype(read()) {
  try {
    return std::forward<Read>(read)();
  } catch (const std::bad_alloc&) {
    FailInput(path, what,
              "is too large to read (out of memory; the limits of each input: "
              "docs/reliability.md)");
  }
}

}  // namespace dualgrid
