#include "nuscenes_tables.hpp"

#include "dualgrid/core/json_input.hpp"

#include <cmath>
#include <stdexcept>

namespace dualgrid::recorded::nuscenes {

namespace {

[[noreturn]] void Bad(const std::filesystem::path& file, const std::string& what) {
  throw std::invalid_argument(file.string() + ": " + what);
}

}  // namespace

std::string Where(const Table& table, const Json& record, const std::string& key) {
  const auto t = record.find("token");
  const std::string token = t != record.end() && t->is_string() ? t->get<std::string>() : "?";
  return table.file.string() + ": record '" + token + "', field '" + key + "': ";
}

const Table& Tables::Get(const std::string& name) {
  if (const auto it = tables_.find(name); it != tables_.end()) return it->second;
  const std::filesystem::path file = dir_ / (name + ".json");
  if (!InputExists(file))
    Bad(file, "missing: table '" + name + "' is needed (a nuScenes version folder?)");
  // nuScenes' largest tables (sample_data.json of v1.0-trainval) pass 64 MiB: the streamed cap.
  Json& j = json_[name];
  j = ReadJsonInput(file, "nuScenes table", kMaxStreamedInputBytes);
  if (!j.is_array()) Bad(file, "expected a JSON array of records");
  Table t;
  t.file = file;
  t.records = &j;
  for (std::size_t i = 0; i < j.size(); ++i) {
    const Json& r = j[i];
    const auto tok = r.is_object() ? r.find("token") : r.end();
    if (!r.is_object() || tok == r.end() || !tok->is_string())
      Bad(file, "record " + std::to_string(i) +
                    ", field 'token': expected an object with a "
                    "string token");
    if (!t.index.emplace(tok->get<std::string>(), i).second)
      Bad(file, "record " + std::to_string(i) + ", field 'token': '" + tok->get<std::string>() +
                    "' given twice");
  }
  return tables_.emplace(name, std::move(t)).first->second;
}

const Json& Tables::Record(const std::string& name, const std::string& token,
                           const std::string& from) {
  const Table& t = Get(name);
  const auto it = t.index.find(token);
  if (it == t.index.end())
    throw std::invalid_argument(from + "token '" + token + "' points nowhere (not in " + name +
                                ".json)");
  return (*t.records)[it->second];
}

std::string Str(const Table& table, const Json& record, const std::string& key) {
  const auto it = record.find(key);
  if (it == record.end() || !it->is_string())
    throw std::invalid_argument(Where(table, record, key) + "expected a string");
  return it->get<std::string>();
}

std::int64_t Int(const Table& table, const Json& record, const std::string& key) {
  const auto it = record.find(key);
  if (it == record.end() || !it->is_number_integer())
    throw std::invalid_argument(Where(table, record, key) + "expected an integer");
  return it->get<std::int64_t>();
}

bool Bool(const Table& table, const Json& record, const std::string& key) {
  const auto it = record.find(key);
  if (it == record.end() || !it->is_boolean())
    throw std::invalid_argument(Where(table, record, key) + "expected true or false");
  return it->get<bool>();
}

std::vector<double> Numbers(const Table& table, const Json& record, const std::string& key,
                            std::size_t n) {
  const auto it = record.find(key);
  if (it == record.end() || !it->is_array() || it->size() != n)
    throw std::invalid_argument(Where(table, record, key) + "expected " + std::to_string(n) +
                                " numbers");
  std::vector<double> v;
  for (const Json& x : *it) {
    if (!x.is_number() || !std::isfinite(x.get<double>()))
      throw std::invalid_argument(Where(table, record, key) + "expected finite numbers, got " +
                                  it->dump());
    v.push_back(x.get<double>());
  }
  if (n == 4) {  // a rotation: a unit quaternion
    const double norm = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + v[3] * v[3]);
    if (!(std::abs(norm - 1.0) < 1e-3))
      throw std::invalid_argument(Where(table, record, key) + "not a unit quaternion (norm " +
                                  std::to_string(norm) + ")");
  }
  return v;
}

double QuaternionYaw(const std::vector<double>& q) {
  return std::atan2(2.0 * (q[0] * q[3] + q[1] * q[2]), 1.0 - 2.0 * (q[2] * q[2] + q[3] * q[3]));
}

std::vector<double> Rotate(const std::vector<double>& q, const std::vector<double>& v) {
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  // The rotation matrix of a unit quaternion.
  const double r[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                          {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                          {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}};
  return {r[0][0] * v[0] + r[0][1] * v[1] + r[0][2] * v[2],
          r[1][0] * v[0] + r[1][1] * v[1] + r[1][2] * v[2],
          r[2][0] * v[0] + r[2][1] * v[1] + r[2][2] * v[2]};
}

}  // namespace dualgrid::recorded::nuscenes
