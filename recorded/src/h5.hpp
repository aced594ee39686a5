// Private: small owners of HDF5 ids and the field-by-field reads and writes of a 1-D compound
// dataset (HDF5 converts any float or integer width to the memory type asked for).
#pragma once

#include <hdf5.h>

#include <cstdint>
#include <string>
#include <vector>

namespace dualgrid::recorded::h5 {

/// Owns one hid_t, closed with `close` (H5Fclose, H5Dclose, H5Tclose, H5Sclose).
class Id {
 public:
  Id() = default;
  Id(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  ~Id() { reset(); }
  Id(Id&& o) noexcept : id_(o.id_), close_(o.close_) { o.id_ = H5I_INVALID_HID; }
  Id& operator=(Id&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = o.id_;
      close_ = o.close_;
      o.id_ = H5I_INVALID_HID;
    }
    return *this;
  }
  Id(const Id&) = delete;
  Id& operator=(const Id&) = delete;
  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }
  void reset() {
    if (id_ >= 0 && close_) close_(id_);
    id_ = H5I_INVALID_HID;
  }

 private:
  hid_t id_ = H5I_INVALID_HID;
  herr_t (*close_)(hid_t) = nullptr;
};

/// The largest ratio of decompressed to stored bytes a filtered (compressed) dataset may claim:
/// deflate's own maximum is about 1032:1.
inline constexpr double kMaxCompressionRatio = 1100.0;

/// HDF5 prints its error stack on every failed call unless told not to: we report our own line.
void Silence();

/// A 1-D dataset of a compound type opened for reading; every error names `file` and the
/// dataset (std::invalid_argument).
class CompoundReader {
 public:
  CompoundReader(hid_t file, const std::string& file_name, const std::string& dataset);
  std::size_t size() const { return n_; }
  bool Has(const std::string& field) const;
  /// A float or integer field as double / int64; throws for a missing field or another class.
  std::vector<double> Doubles(const std::string& field) const;
  std::vector<std::int64_t> Ints(const std::string& field) const;
  /// A string field (fixed-length or variable-length bytes), trailing NULs removed.
  std::vector<std::string> Strings(const std::string& field) const;

 private:
  int Member(const std::string& field, bool numeric) const;
  /// Throws when `rows` could not fit in the file (see kMaxCompressionRatio).
  void CheckDeclaredRows(hid_t file, hsize_t rows) const;
  [[noreturn]] void Fail(const std::string& field, const std::string& what) const;

  std::string where_;  // "file: dataset 'name'"
  Id dataset_, type_;
  std::size_t n_ = 0;
};

/// Builds a compound type member by member (packed), then writes a 1-D dataset field by field.
class CompoundWriter {
 public:
  void AddDouble(const std::string& field);
  void AddUInt64(const std::string& field);
  void AddUInt8(const std::string& field);
  void AddString(const std::string& field, std::size_t length);
  /// Creates `dataset` with `n` rows in `file`; then Write* each field (all must be written).
  void Create(hid_t file, const std::string& file_name, const std::string& dataset, std::size_t n);
  void WriteDoubles(const std::string& field, const std::vector<double>& v);
  void WriteUInt64(const std::string& field, const std::vector<std::uint64_t>& v);
  void WriteUInt8(const std::string& field, const std::vector<std::uint8_t>& v);
  void WriteStrings(const std::string& field, const std::vector<std::string>& v);

 private:
  struct Member {
    std::string name;
    hid_t type;  // a predefined type, or a string type owned by `strings_`
    std::size_t size;
  };
  void WriteField(const std::string& field, hid_t mem_type, std::size_t size, const void* data);
  [[noreturn]] void Fail(const std::string& what) const;

  std::vector<Member> members_;
  std::vector<Id> strings_;
  std::string where_;
  Id dataset_;
};

}  // namespace dualgrid::recorded::h5
