// PCD v0.7 binary files (docs/recorded-data.md, "nuScenes").
#include "dualgrid/recorded/pcd.hpp"

#include "dualgrid/core/input_file.hpp"
#include "dualgrid/core/write_file.hpp"

#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

namespace dualgrid::recorded {

static_assert(std::endian::native == std::endian::little, "PCD binary data are little-endian");

namespace {

// Longest PCD header line [bytes]: a header line names at most a few dozen fields.
constexpr std::uint64_t kMaxHeaderLine = 4096;

[[noreturn]] void Bad(const std::filesystem::path& file, const std::string& what) {
  throw std::invalid_argument(file.string() + ": " + what);
}

bool ValidType(char type, int size) {
  if (type == 'F') return size == 4 || size == 8;
  if (type == 'I' || type == 'U') return size == 1 || size == 2 || size == 4 || size == 8;
  return false;
}

// One value of `field` at `p`.
double Decode(const PcdField& field, const unsigned char* p) {
  auto load = [p](auto v) {
    std::memcpy(&v, p, sizeof v);
    return static_cast<double>(v);
  };
  if (field.type == 'F') return field.size == 4 ? load(float{}) : load(double{});
  if (field.type == 'I') {
    switch (field.size) {
      case 1:
        return load(std::int8_t{});
      case 2:
        return load(std::int16_t{});
      case 4:
        return load(std::int32_t{});
      default:
        return load(std::int64_t{});
    }
  }
  switch (field.size) {
    case 1:
      return load(std::uint8_t{});
    case 2:
      return load(std::uint16_t{});
    case 4:
      return load(std::uint32_t{});
    default:
      return load(std::uint64_t{});
  }
}

void Encode(const PcdField& field, double v, unsigned char* p) {
  auto store = [p](auto x) { std::memcpy(p, &x, sizeof x); };
  if (field.type == 'F') return field.size == 4 ? store(static_cast<float>(v)) : store(v);
  const long long i = std::llround(v);
  if (field.type == 'I') {
    switch (field.size) {
      case 1:
        return store(static_cast<std::int8_t>(i));
      case 2:
        return store(static_cast<std::int16_t>(i));
      case 4:
        return store(static_cast<std::int32_t>(i));
      default:
        return store(static_cast<std::int64_t>(i));
    }
  }
  switch (field.size) {
    case 1:
      return store(static_cast<std::uint8_t>(i));
    case 2:
      return store(static_cast<std::uint16_t>(i));
    case 4:
      return store(static_cast<std::uint32_t>(i));
    default:
      return store(static_cast<std::uint64_t>(i));
  }
}

// The header's lines up to and including DATA, as key -> the words after it.
std::map<std::string, std::vector<std::string>> ReadHeader(const std::filesystem::path& file,
                                                           InputStream& in) {
  std::map<std::string, std::vector<std::string>> keys;
  std::string line;
  while (in.ReadLine(&line, kMaxHeaderLine)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream words(line);
    std::string key, w;
    words >> key;
    std::vector<std::string>& v = keys[key];
    while (words >> w) v.push_back(w);
    if (key == "DATA") return keys;
    if (keys.size() > 32) break;
  }
  Bad(file, "header key 'DATA' is missing (not a PCD file?)");
}

long long HeaderInt(const std::filesystem::path& file,
                    const std::map<std::string, std::vector<std::string>>& keys,
                    const std::string& key) {
  const auto it = keys.find(key);
  if (it == keys.end() || it->second.size() != 1)
    Bad(file, "header key '" + key + "': expected one whole number");
  std::size_t used = 0;
  long long v = -1;
  try {
    v = std::stoll(it->second[0], &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != it->second[0].size() || v < 0)
    Bad(file,
        "header key '" + key + "': expected a whole number >= 0, got '" + it->second[0] + "'");
  return v;
}

std::vector<PcdField> ParseFields(const std::filesystem::path& file,
                                  const std::map<std::string, std::vector<std::string>>& keys) {
  auto words = [&](const std::string& key) -> const std::vector<std::string>& {
    const auto it = keys.find(key);
    if (it == keys.end() || it->second.empty()) Bad(file, "header key '" + key + "' is missing");
    return it->second;
  };
  const auto& names = words("FIELDS");
  const auto& sizes = words("SIZE");
  const auto& types = words("TYPE");
  for (const char* key : {"SIZE", "TYPE"})
    if (words(key).size() != names.size())
      Bad(file, std::string("header key '") + key + "': " + std::to_string(words(key).size()) +
                    " entries for " + std::to_string(names.size()) + " FIELDS");
  if (keys.count("COUNT")) {
    const auto& counts = words("COUNT");
    if (counts.size() != names.size())
      Bad(file, "header key 'COUNT': " + std::to_string(counts.size()) + " entries for " +
                    std::to_string(names.size()) + " FIELDS");
    for (std::size_t f = 0; f < counts.size(); ++f)
      if (counts[f] != "1")
        Bad(file, "header key 'COUNT': field '" + names[f] + "' has count " + counts[f] +
                      " (only 1 is read)");
  }
  std::vector<PcdField> fields;
  for (std::size_t f = 0; f < names.size(); ++f) {
    PcdField x;
    x.name = names[f];
    x.type = types[f].size() == 1 ? types[f][0] : '?';
    x.size =
        sizes[f].size() == 1 && sizes[f][0] >= '1' && sizes[f][0] <= '8' ? sizes[f][0] - '0' : 0;
    if (!ValidType(x.type, x.size))
      Bad(file, "header keys 'TYPE'/'SIZE': field '" + x.name + "' has type " + types[f] +
                    " of size " + sizes[f] + " (F 4/8, I or U 1/2/4/8 expected)");
    fields.push_back(x);
  }
  return fields;
}

}  // namespace

const std::vector<double>* PcdCloud::Column(const std::string& name) const {
  for (std::size_t f = 0; f < fields.size(); ++f)
    if (fields[f].name == name) return &columns[f];
  return nullptr;
}

PcdCloud ReadPcd(const std::filesystem::path& file) {
  const std::uint64_t file_size = CheckInputFile(file, "PCD file");
  InputStream in(file, "PCD file");
  const auto keys = ReadHeader(file, in);
  PcdCloud cloud;
  cloud.fields = ParseFields(file, keys);
  const long long width = HeaderInt(file, keys, "WIDTH");
  const long long height = HeaderInt(file, keys, "HEIGHT");
  const long long points = HeaderInt(file, keys, "POINTS");
  if (height != 1) Bad(file, "header key 'HEIGHT': " + std::to_string(height) + " (1 expected)");
  if (points != width * height)
    Bad(file, "header key 'POINTS': " + std::to_string(points) + " is not WIDTH x HEIGHT (" +
                  std::to_string(width * height) + ")");
  const auto& data = keys.at("DATA");
  if (data.size() != 1 || data[0] != "binary")
    Bad(file, "header key 'DATA': '" + (data.empty() ? std::string() : data[0]) +
                  "' (only binary is read)");
  std::size_t row = 0;
  for (const PcdField& f : cloud.fields) row += static_cast<std::size_t>(f.size);
  if (row == 0) Bad(file, "header key 'FIELDS': no fields");
  // Declared points are allocated before they are read: no more than the file holds.
  if (static_cast<std::uint64_t>(points) > file_size / row)
    Bad(file, "header key 'POINTS': " + std::to_string(points) + " points of " +
                  std::to_string(row) + " bytes do not fit in the file's " +
                  std::to_string(file_size) + " bytes (truncated or damaged?)");
  const std::size_t need = row * static_cast<std::size_t>(points);
  std::vector<unsigned char> bytes(need);
  const std::size_t got = in.ReadExactly(reinterpret_cast<char*>(bytes.data()), need);
  if (got != need)
    Bad(file, "data: " + std::to_string(got) + " bytes after the header, fewer than its " +
                  "POINTS x row size (" + std::to_string(points) + " x " + std::to_string(row) +
                  " = " + std::to_string(need) + ")");
  cloud.columns.assign(cloud.fields.size(), std::vector<double>(static_cast<std::size_t>(points)));
  for (std::size_t i = 0; i < static_cast<std::size_t>(points); ++i) {
    const unsigned char* p = bytes.data() + i * row;
    for (std::size_t f = 0; f < cloud.fields.size(); ++f) {
      cloud.columns[f][i] = Decode(cloud.fields[f], p);
      p += cloud.fields[f].size;
    }
  }
  return cloud;
}

void WritePcd(const std::filesystem::path& file, const PcdCloud& cloud) {
  if (cloud.columns.size() != cloud.fields.size())
    throw std::invalid_argument("WritePcd: one column per field expected");
  const std::size_t n = cloud.size();
  std::size_t row = 0;
  for (std::size_t f = 0; f < cloud.fields.size(); ++f) {
    if (cloud.columns[f].size() != n || !ValidType(cloud.fields[f].type, cloud.fields[f].size))
      throw std::invalid_argument("WritePcd: field '" + cloud.fields[f].name +
                                  "': wrong length or type");
    row += static_cast<std::size_t>(cloud.fields[f].size);
  }
  std::ostringstream h;
  h << "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS";
  for (const PcdField& f : cloud.fields) h << ' ' << f.name;
  h << "\nSIZE";
  for (const PcdField& f : cloud.fields) h << ' ' << f.size;
  h << "\nTYPE";
  for (const PcdField& f : cloud.fields) h << ' ' << f.type;
  h << "\nCOUNT";
  for (std::size_t f = 0; f < cloud.fields.size(); ++f) h << " 1";
  h << "\nWIDTH " << n << "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " << n << "\nDATA binary\n";
  std::vector<unsigned char> bytes(row * n);
  for (std::size_t i = 0; i < n; ++i) {
    unsigned char* p = bytes.data() + i * row;
    for (std::size_t f = 0; f < cloud.fields.size(); ++f) {
      Encode(cloud.fields[f], cloud.columns[f][i], p);
      p += cloud.fields[f].size;
    }
  }
  const std::string header = h.str();
  WriteFileChecked(
      file,
      {header, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()), "\n"});
}

}  // namespace dualgrid::recorded
