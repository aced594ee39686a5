// The parameter tables of the scenario loader: one row per YAML key of a parameter struct, read
// by the section readers and written by ConfigToJson through the same table.
#pragma once

#include <cstddef>
#include <type_traits>
#include <vector>

#include <nlohmann/json.hpp>

#include "dualgrid/filter/params.hpp"
#include "dualgrid/radar_model/radar_model.hpp"
#include "sections.hpp"
#include "yaml_reader.hpp"

namespace dualgrid::scenario::detail {

// One table per parameter struct: the YAML key, the member, and whether the file gives it in
// degrees. The loader reads and ConfigToJson writes through the same tables, so a new parameter
// is one line here.
template <typename S, typename T>
struct Field {
  const char* key;
  T S::*member;
  bool degrees = false;
};
using FP = filter::FilterParams;
using SP = radar::SensorParams;
inline const Field<FP, double> kFilterDoubles[] = {
    {"length_x", &FP::length_x},
    {"width_y", &FP::width_y},
    {"resolution", &FP::resolution},
    {"process_noise_position", &FP::process_noise_position},
    {"process_noise_velocity", &FP::process_noise_velocity},
    {"persistence", &FP::persistence},
    {"birth_probability", &FP::birth_probability},
    {"birth_max_tangential_speed", &FP::birth_max_tangential_speed},
    {"birth_sigma_radial", &FP::birth_sigma_radial},
    {"doppler_fit_radius", &FP::doppler_fit_radius},
    {"doppler_fit_sigma", &FP::doppler_fit_sigma},
    {"birth_fit_uniform_share", &FP::birth_fit_uniform_share},
    {"max_speed", &FP::max_speed},
    {"sigma_f", &FP::sigma_f},
    {"sigma_static_distance", &FP::sigma_static_distance},
    {"sigma_static_velocity", &FP::sigma_static_velocity},
    {"sigma_v", &FP::sigma_v},
    {"cutoff_sigmas", &FP::cutoff_sigmas},
    {"occupied_mass", &FP::occupied_mass},
    {"free_mass", &FP::free_mass},
    {"free_mass_no_return", &FP::free_mass_no_return},
    {"free_angle_bin_deg", &FP::free_angle_bin, true},
    {"free_decay", &FP::free_decay},
    {"static_persistence", &FP::static_persistence},
    {"static_gain", &FP::static_gain},
    {"static_speed", &FP::static_speed},
    {"decay_eps", &FP::decay_eps},
};
inline const Field<FP, int> kFilterInts[] = {
    {"num_particles", &FP::num_particles},
    {"num_birth", &FP::num_birth},
    {"free_bin_dilation", &FP::free_bin_dilation},
};
inline const Field<SP, double> kSensorDoubles[] = {
    {"fov_deg", &SP::fov, true},
    {"min_range", &SP::min_range},
    {"max_range", &SP::max_range},
    {"min_range_rate", &SP::min_range_rate},
    {"max_range_rate", &SP::max_range_rate},
    {"range_resolution", &SP::range_resolution},
    {"azimuth_resolution_deg", &SP::azimuth_resolution, true},
    {"range_rate_resolution", &SP::range_rate_resolution},
    {"range_accuracy", &SP::range_accuracy},
    {"azimuth_accuracy_deg", &SP::azimuth_accuracy, true},
    {"range_rate_accuracy", &SP::range_rate_accuracy},
    {"reference_range", &SP::reference_range},
    {"reference_rcs_dbsm", &SP::reference_rcs_dbsm},
    {"reference_pd", &SP::reference_pd},
    {"false_alarm_rate", &SP::false_alarm_rate},
    {"update_period", &SP::update_period},
};

template <typename S, typename T, std::size_t N>
void ReadFields(MapReader& r, const Field<S, T> (&fields)[N], S* out) {
  for (const auto& f : fields) {
    if constexpr (std::is_same_v<T, double>) {
      if (f.degrees) {
        r.ReadDegrees(f.key, &(out->*f.member));
        continue;
      }
    }
    r.Read(f.key, &(out->*f.member));
  }
}

template <typename S, typename T, std::size_t N>
void WriteFields(const Field<S, T> (&fields)[N], const S& in, nlohmann::json* j) {
  for (const auto& f : fields) {
    if constexpr (std::is_same_v<T, double>) {
      (*j)[f.key] = f.degrees ? RadToDeg(in.*f.member) : in.*f.member;
    } else {
      (*j)[f.key] = in.*f.member;
    }
  }
}

// The aliases of a parameter table's degree rows: the validator's field is the key without
// "_deg" ("fov" -> "fov_deg").
template <typename S, typename T, std::size_t N>
std::vector<KeyAlias> DegreeAliases(const Field<S, T> (&fields)[N]) {
  std::vector<KeyAlias> out;
  for (const auto& f : fields) {
    const std::string_view key = f.key;
    if (f.degrees && key.ends_with("_deg"))
      out.push_back({key.substr(0, key.size() - 4), key, true});
  }
  return out;
}

}  // namespace dualgrid::scenario::detail
