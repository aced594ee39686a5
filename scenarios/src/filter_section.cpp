#include <cmath>
#include <cstdio>

#include "fields.hpp"
#include "sections.hpp"

namespace dualgrid::scenario::detail {

namespace {

// Reads a switch given by name into *out, naming the accepted values on error.
template <typename E>
void ReadSwitch(MapReader& r, const std::string& key, std::optional<E> (*parse)(std::string_view),
                const char* accepted, E* out) {
  if (!r.Has(key)) return;
  std::string name;
  r.Read(key, &name);
  const std::optional<E> v = parse(name);
  if (!v) r.Fail(key, std::string("expected ") + accepted + ", got '" + name + "'");
  *out = *v;
}

void ReadGridPlacement(MapReader& r, const filter::FilterParams& f, GridPlacement* g) {
  if (r.Has("frame")) {
    std::string frame;
    r.Read("frame", &frame);
    if (frame == "world")
      g->frame = GridPlacement::Frame::kWorld;
    else if (frame == "heading")
      g->frame = GridPlacement::Frame::kHeading;
    else if (frame == "follow")
      g->frame = GridPlacement::Frame::kFollow;
    else
      r.Fail("frame", "expected 'follow', 'heading' or 'world', got '" + frame + "'");
  }
  if (r.Has("realign_deg")) {
    if (g->frame != GridPlacement::Frame::kFollow)
      r.Fail("realign_deg", "is used only with frame: follow (the grid that turns with the road)");
    r.Read("realign_deg", &g->realign_deg);
    if (!(g->realign_deg > 0.0 && g->realign_deg <= 90.0))
      r.Fail("realign_deg", "expected an angle in (0, 90] deg, got " + Shown(g->realign_deg));
  }
  auto read_edge = [&](const char* key, double extent, const char* extent_key, double* out) {
    if (!r.Has(key)) return;
    r.Read(key, out);
    if (!(std::isfinite(*out) && *out >= 0.0 && *out <= extent)) {
      char buf[160];
      std::snprintf(buf, sizeof buf, "expected a distance in [0, %s = %g] m, got %g", extent_key,
                    extent, *out);
      r.Fail(key, buf);
    }
  };
  read_edge("ahead", f.length_x, "length_x", &g->ahead);
  read_edge("left", f.width_y, "width_y", &g->left);
}

}  // namespace

void ReadFilter(MapReader& root, ScenarioConfig* config) {
  filter::FilterParams* f = &config->filter;
  auto r = root.Map("filter");
  if (!r) return;
  // A preset first: the keys below override it.
  if (r->Has("preset")) {
    r->Read("preset", &config->filter_preset);
    const std::optional<filter::FilterParams> preset = filter::Preset(config->filter_preset);
    if (!preset)
      r->Fail("preset", "expected one of " + std::string(filter::PresetNames()) + ", got '" +
                            config->filter_preset + "'");
    *f = *preset;
  }
  ReadFields(*r, kFilterDoubles, f);
  ReadFields(*r, kFilterInts, f);
  std::string mode(filter::ToString(f->mode));
  r->Read("mode", &mode);
  const auto parsed = filter::ParseWeightMode(mode);
  if (!parsed) r->Fail("mode", "expected 'position', 'velocity' or 'dual', got '" + mode + "'");
  f->mode = *parsed;
  ReadSwitch(*r, "zero_likelihood", filter::ParseZeroLikelihood, "'keep_prediction' or 'literal'",
             &f->zero_likelihood);
  ReadSwitch(*r, "velocity_likelihood", filter::ParseVelocityLikelihood,
             "'vector', 'radial' or 'radial_fit'", &f->velocity_likelihood);
  ReadSwitch(*r, "normalisation", filter::ParseNormalisation, "'per_cell' or 'literal'",
             &f->normalisation);
  constexpr const char* kBirthNames = "'doppler', 'uniform' or 'doppler_fit'";
  if (r->IsMap("birth_velocity")) {
    // Per mode: {position: uniform, velocity: doppler, dual: doppler}.
    auto per_mode = r->Map("birth_velocity");
    for (filter::WeightMode m : {filter::WeightMode::kPosition, filter::WeightMode::kVelocity,
                                 filter::WeightMode::kDual}) {
      filter::BirthVelocity v = f->birth_velocity;
      const std::string key(filter::ToString(m));
      if (!per_mode->Has(key)) continue;
      ReadSwitch(*per_mode, key, filter::ParseBirthVelocity, kBirthNames, &v);
      config->birth_velocity_by_mode[m] = v;
    }
    per_mode->Finish();
  } else {
    ReadSwitch(*r, "birth_velocity", filter::ParseBirthVelocity, kBirthNames, &f->birth_velocity);
  }
  ReadGridPlacement(*r, *f, &config->grid);  // after length_x / width_y: it checks against them
  r->Finish();
  std::string error;
  if (!f->IsValid(&error)) Invalid(root.file(), "filter", error, DegreeAliases(kFilterDoubles));
}

}  // namespace dualgrid::scenario::detail
