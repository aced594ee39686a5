#include "h5.hpp"

#include <algorithm>
#include <cstring>
#include <stdexcept>

namespace dualgrid::recorded::h5 {

void Silence() { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); }

namespace {

const char* ClassName(H5T_class_t c) {
  switch (c) {
    case H5T_INTEGER:
      return "integer";
    case H5T_FLOAT:
      return "float";
    case H5T_STRING:
      return "string";
    case H5T_COMPOUND:
      return "compound";
    case H5T_ARRAY:
      return "array";
    case H5T_ENUM:
      return "enum";
    case H5T_VLEN:
      return "variable-length sequence";
    default:
      return "another HDF5 class";
  }
}

}  // namespace

CompoundReader::CompoundReader(hid_t file, const std::string& file_name, const std::string& dataset)
    : where_(file_name + ": dataset '" + dataset + "'") {
  if (H5Lexists(file, dataset.c_str(), H5P_DEFAULT) <= 0)
    throw std::invalid_argument(where_ + " is missing");
  dataset_ = Id(H5Dopen2(file, dataset.c_str(), H5P_DEFAULT), H5Dclose);
  if (!dataset_.valid()) throw std::invalid_argument(where_ + " cannot be opened (not a dataset?)");
  type_ = Id(H5Dget_type(dataset_.get()), H5Tclose);
  if (!type_.valid() || H5Tget_class(type_.get()) != H5T_COMPOUND)
    throw std::invalid_argument(where_ + ": expected a structured (compound) array, got " +
                                ClassName(H5Tget_class(type_.get())));
  const Id space(H5Dget_space(dataset_.get()), H5Sclose);
  if (!space.valid() || H5Sget_simple_extent_ndims(space.get()) != 1)
    throw std::invalid_argument(where_ + ": expected a one-dimensional array");
  hsize_t dims[1] = {0};
  H5Sget_simple_extent_dims(space.get(), dims, nullptr);
  CheckDeclaredRows(file, dims[0]);
  n_ = static_cast<std::size_t>(dims[0]);
}

void CompoundReader::CheckDeclaredRows(hid_t file, hsize_t rows) const {
  // The rows a dataset declares are allocated before they are read: bounded by what the file
  // can hold, rows x row size <= the file's size, times kMaxCompressionRatio when filters
  // (deflate) are on; a dataset of fill values never written is refused with them.
  hsize_t file_size = 0;
  if (H5Fget_filesize(file, &file_size) < 0) throw std::invalid_argument(where_ + ": unreadable");
  const Id dcpl(H5Dget_create_plist(dataset_.get()), H5Pclose);
  const bool filtered = dcpl.valid() && H5Pget_nfilters(dcpl.get()) > 0;
  const double row_bytes = static_cast<double>(std::max<std::size_t>(1, H5Tget_size(type_.get())));
  const double cap = static_cast<double>(file_size) * (filtered ? kMaxCompressionRatio : 1.0);
  if (static_cast<double>(rows) * row_bytes > cap)
    throw std::invalid_argument(
        where_ + ": declares " + std::to_string(rows) + " rows of " +
        std::to_string(static_cast<std::size_t>(row_bytes)) + " bytes, more than the file's " +
        std::to_string(file_size) + " bytes can hold" +
        (filtered ? " at a compression ratio of " +
                        std::to_string(static_cast<int>(kMaxCompressionRatio))
                  : std::string(" (uncompressed)")) +
        " (truncated or damaged?)");
}

void CompoundReader::Fail(const std::string& field, const std::string& what) const {
  throw std::invalid_argument(where_ + ", field '" + field + "': " + what);
}

bool CompoundReader::Has(const std::string& field) const {
  return H5Tget_member_index(type_.get(), field.c_str()) >= 0;
}

int CompoundReader::Member(const std::string& field, bool numeric) const {
  const int idx = H5Tget_member_index(type_.get(), field.c_str());
  if (idx < 0) Fail(field, "missing");
  const H5T_class_t c = H5Tget_member_class(type_.get(), static_cast<unsigned>(idx));
  if (numeric && c != H5T_FLOAT && c != H5T_INTEGER)
    Fail(field, std::string("expected a float or integer, got ") + ClassName(c));
  if (!numeric && c != H5T_STRING)
    Fail(field, std::string("expected bytes (a string), got ") + ClassName(c));
  return idx;
}

std::vector<double> CompoundReader::Doubles(const std::string& field) const {
  Member(field, true);
  std::vector<double> out(n_);
  const Id mt(H5Tcreate(H5T_COMPOUND, sizeof(double)), H5Tclose);
  H5Tinsert(mt.get(), field.c_str(), 0, H5T_NATIVE_DOUBLE);
  if (n_ > 0 && H5Dread(dataset_.get(), mt.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()) < 0)
    Fail(field, "read failed (file truncated or damaged?)");
  return out;
}

std::vector<std::int64_t> CompoundReader::Ints(const std::string& field) const {
  const int idx = Member(field, true);
  if (H5Tget_member_class(type_.get(), static_cast<unsigned>(idx)) != H5T_INTEGER)
    Fail(field, "expected an integer, got a float");
  std::vector<std::int64_t> out(n_);
  const Id mt(H5Tcreate(H5T_COMPOUND, sizeof(std::int64_t)), H5Tclose);
  H5Tinsert(mt.get(), field.c_str(), 0, H5T_NATIVE_INT64);
  if (n_ > 0 && H5Dread(dataset_.get(), mt.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()) < 0)
    Fail(field, "read failed (file truncated or damaged, or a value out of the integer range?)");
  return out;
}

std::vector<std::string> CompoundReader::Strings(const std::string& field) const {
  const int idx = Member(field, false);
  const Id ft(H5Tget_member_type(type_.get(), static_cast<unsigned>(idx)), H5Tclose);
  std::vector<std::string> out(n_);
  if (n_ == 0) return out;
  if (H5Tis_variable_str(ft.get()) > 0) {
    const Id st(H5Tcopy(H5T_C_S1), H5Tclose);
    H5Tset_size(st.get(), H5T_VARIABLE);
    const Id mt(H5Tcreate(H5T_COMPOUND, sizeof(char*)), H5Tclose);
    H5Tinsert(mt.get(), field.c_str(), 0, st.get());
    std::vector<char*> ptr(n_, nullptr);
    if (H5Dread(dataset_.get(), mt.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, ptr.data()) < 0)
      Fail(field, "read failed (file truncated or damaged?)");
    for (std::size_t i = 0; i < n_; ++i) out[i] = ptr[i] ? ptr[i] : "";
    const Id space(H5Dget_space(dataset_.get()), H5Sclose);
    H5Dvlen_reclaim(mt.get(), space.get(), H5P_DEFAULT, ptr.data());
    return out;
  }
  const std::size_t len = H5Tget_size(ft.get());
  if (len == 0 || len > 4096) Fail(field, "string length " + std::to_string(len) + " out of range");
  const Id st(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(st.get(), len);
  H5Tset_strpad(st.get(), H5T_STR_NULLPAD);
  const Id mt(H5Tcreate(H5T_COMPOUND, len), H5Tclose);
  H5Tinsert(mt.get(), field.c_str(), 0, st.get());
  std::vector<char> buf(n_ * len);
  if (H5Dread(dataset_.get(), mt.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, buf.data()) < 0)
    Fail(field, "read failed (file truncated or damaged?)");
  for (std::size_t i = 0; i < n_; ++i) {
    const char* s = buf.data() + i * len;
    out[i].assign(s, strnlen(s, len));
  }
  return out;
}

void CompoundWriter::AddDouble(const std::string& field) {
  members_.push_back({field, H5T_IEEE_F64LE, 8});
}
void CompoundWriter::AddUInt64(const std::string& field) {
  members_.push_back({field, H5T_STD_U64LE, 8});
}
void CompoundWriter::AddUInt8(const std::string& field) {
  members_.push_back({field, H5T_STD_U8LE, 1});
}
void CompoundWriter::AddString(const std::string& field, std::size_t length) {
  Id st(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(st.get(), length);
  H5Tset_strpad(st.get(), H5T_STR_NULLPAD);
  members_.push_back({field, st.get(), length});
  strings_.push_back(std::move(st));
}

void CompoundWriter::Fail(const std::string& what) const {
  throw std::runtime_error(where_ + ": " + what);
}

void CompoundWriter::Create(hid_t file, const std::string& file_name, const std::string& dataset,
                            std::size_t n) {
  where_ = file_name + ": dataset '" + dataset + "'";
  std::size_t size = 0;
  for (const Member& m : members_) size += m.size;
  const Id type(H5Tcreate(H5T_COMPOUND, size), H5Tclose);
  std::size_t offset = 0;
  for (const Member& m : members_) {
    if (H5Tinsert(type.get(), m.name.c_str(), offset, m.type) < 0) Fail("bad field " + m.name);
    offset += m.size;
  }
  const hsize_t dims[1] = {static_cast<hsize_t>(n)};
  const Id space(H5Screate_simple(1, dims, nullptr), H5Sclose);
  dataset_ = Id(H5Dcreate2(file, dataset.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT,
                           H5P_DEFAULT),
                H5Dclose);
  if (!dataset_.valid()) Fail("cannot be created");
}

void CompoundWriter::WriteField(const std::string& field, hid_t mem_type, std::size_t size,
                                const void* data) {
  const Id mt(H5Tcreate(H5T_COMPOUND, size), H5Tclose);
  H5Tinsert(mt.get(), field.c_str(), 0, mem_type);
  if (H5Dwrite(dataset_.get(), mt.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0)
    Fail("writing field '" + field + "' failed (disk full?)");
}

void CompoundWriter::WriteDoubles(const std::string& field, const std::vector<double>& v) {
  WriteField(field, H5T_NATIVE_DOUBLE, sizeof(double), v.data());
}
void CompoundWriter::WriteUInt64(const std::string& field, const std::vector<std::uint64_t>& v) {
  WriteField(field, H5T_NATIVE_UINT64, sizeof(std::uint64_t), v.data());
}
void CompoundWriter::WriteUInt8(const std::string& field, const std::vector<std::uint8_t>& v) {
  WriteField(field, H5T_NATIVE_UINT8, 1, v.data());
}
void CompoundWriter::WriteStrings(const std::string& field, const std::vector<std::string>& v) {
  std::size_t len = 0;
  for (const Member& m : members_)
    if (m.name == field) len = m.size;
  std::vector<char> buf(v.size() * len, '\0');
  for (std::size_t i = 0; i < v.size(); ++i)
    std::memcpy(buf.data() + i * len, v[i].data(), std::min(len, v[i].size()));
  const Id st(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(st.get(), len);
  H5Tset_strpad(st.get(), H5T_STR_NULLPAD);
  WriteField(field, st.get(), len, buf.data());
}

}  // namespace dualgrid::recorded::h5
