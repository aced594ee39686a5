// Point Cloud Data files (PCL's PCD v0.7), as nuScenes stores its radar scans: a text header
// (VERSION, FIELDS, SIZE, TYPE, COUNT, WIDTH, HEIGHT, VIEWPOINT, POINTS, DATA) followed by the
// points, row by row, little-endian. Only `DATA binary`, HEIGHT 1 and COUNT 1 are read (what
// nuScenes writes); docs/recorded-data.md, "nuScenes".
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace dualgrid::recorded {

/// One field of a PCD file: its name, type ('F' float, 'I' signed, 'U' unsigned) and size in
/// bytes (F: 4 or 8; I, U: 1, 2, 4 or 8).
struct PcdField {
  std::string name;
  char type = 'F';
  int size = 4;
};

/// A point cloud read from or to be written to a PCD file: `columns[f][i]` is field f of point i
/// (every type widened to double: integers up to 2^53 are exact, float32 values exactly).
struct PcdCloud {
  std::vector<PcdField> fields;
  std::vector<std::vector<double>> columns;

  std::size_t size() const { return columns.empty() ? 0 : columns.front().size(); }
  /// The column of `name`, or nullptr.
  const std::vector<double>* Column(const std::string& name) const;
};

/// Reads a binary PCD file. Throws std::invalid_argument of one line naming the file and the
/// header key (or the byte count) of bad input: a missing or malformed key, an unsupported
/// type or size, COUNT other than 1, HEIGHT other than 1, POINTS != WIDTH x HEIGHT, DATA other
/// than binary, or fewer bytes after the header than POINTS x the row size. Trailing bytes are
/// allowed (the devkit's own reader needs at least one).
PcdCloud ReadPcd(const std::filesystem::path& file);

/// Writes `cloud` as a binary PCD v0.7 file (each value converted to its field's type; one
/// newline after the data, which the devkit's reader needs). Throws std::invalid_argument for
/// columns of unequal length and std::runtime_error naming the file when a write fails.
void WritePcd(const std::filesystem::path& file, const PcdCloud& cloud);

}  // namespace dualgrid::recorded
