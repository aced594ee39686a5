"""FilterParams / SensorParams / presets of the Python module (python/src/filter_bindings.cpp,
radar_bindings.cpp)."""

import copy
import math
import pickle
import unittest

import dualgrid

# Every field of filter::FilterParams (filter/include/dualgrid/filter/params.hpp) in declaration
# order: a field added in C++ but not bound (or bound twice) fails test_every_field_is_bound.
FILTER_FIELDS = [
    "length_x", "width_y", "resolution", "num_particles", "num_birth", "process_noise_position",
    "process_noise_velocity", "persistence", "birth_probability", "birth_max_tangential_speed",
    "max_speed", "birth_sigma_radial", "doppler_fit_radius", "doppler_fit_sigma",
    "birth_fit_uniform_share", "sigma_f", "sigma_static_distance",
    "sigma_static_velocity", "sigma_v", "cutoff_sigmas", "occupied_mass", "free_mass",
    "free_mass_no_return", "free_angle_bin", "free_bin_dilation", "free_decay",
    "static_persistence", "static_gain", "static_speed", "decay_eps", "cycle", "mode",
    "birth_velocity",
    "zero_likelihood", "velocity_likelihood", "normalisation"
]
SWITCHES = ["birth_velocity", "zero_likelihood", "velocity_likelihood", "normalisation"]


class FilterParamsTest(unittest.TestCase):

    def test_every_field_is_bound(self):
        p = dualgrid.FilterParams()
        self.assertEqual(list(p.to_dict()), FILTER_FIELDS)

    def test_defaults_are_the_cpp_defaults(self):
        p = dualgrid.FilterParams()
        self.assertEqual((p.length_x, p.width_y, p.resolution), (200.0, 25.0, 0.5))
        self.assertEqual((p.num_particles, p.num_birth), (10000, 1000))
        self.assertEqual((p.cells_x, p.cells_y), (400, 50))
        self.assertEqual(p.mode, "dual")
        self.assertEqual(p.birth_velocity, "doppler_fit")
        self.assertEqual(p.zero_likelihood, "keep_prediction")
        self.assertEqual(p.velocity_likelihood, "radial_fit")
        self.assertEqual(p.normalisation, "per_cell")
        self.assertTrue(p.is_valid())
        self.assertIsNone(p.validate())

    def test_fields_read_and_write(self):
        p = dualgrid.FilterParams()
        for i, name in enumerate(FILTER_FIELDS):
            value = getattr(p, name)
            if isinstance(value, str):
                continue
            new = value + 1 if isinstance(value, int) else value * 0.5 + 0.001 * i
            setattr(p, name, new)
            self.assertEqual(getattr(p, name), new, name)
        p.mode = "position"
        self.assertEqual(p.mode, "position")

    def test_keyword_constructor(self):
        p = dualgrid.FilterParams(num_particles=500, mode="velocity", sigma_v=2.0)
        self.assertEqual((p.num_particles, p.mode, p.sigma_v), (500, "velocity", 2.0))
        with self.assertRaisesRegex(TypeError, "unknown field 'num_particle'"):
            dualgrid.FilterParams(num_particle=5)
        with self.assertRaises(TypeError):
            dualgrid.FilterParams(num_particles=1.5)  # an int field

    def test_enum_fields_reject_unknown_names(self):
        p = dualgrid.FilterParams()
        accepted = {
            "mode": ["position", "velocity", "dual"],
            "birth_velocity": ["doppler", "uniform", "doppler_fit"],
            "zero_likelihood": ["keep_prediction", "literal"],
            "velocity_likelihood": ["vector", "radial", "radial_fit"],
            "normalisation": ["per_cell", "literal"],
        }
        for name, values in accepted.items():
            for v in values:
                setattr(p, name, v)
                self.assertEqual(getattr(p, name), v)
            with self.assertRaisesRegex(ValueError, f"{name}: unknown value 'bogus'.*{values[0]}"):
                setattr(p, name, "bogus")

    def test_validate_names_the_field(self):
        cases = {
            "resolution": -1.0,
            "num_particles": 0,
            "persistence": 0.0,
            "occupied_mass": 1.0,
            "free_mass_no_return": 0.9,  # > free_mass
            "decay_eps": math.nan,
        }
        for name, bad in cases.items():
            p = dualgrid.FilterParams(**{name: bad})
            self.assertFalse(p.is_valid(), name)
            # core/validation.hpp's form: the field, the value given, what was expected.
            with self.assertRaisesRegex(ValueError, f"FilterParams: {name} = {bad:g}: expected"):
                p.validate()
            with self.assertRaisesRegex(ValueError, name):
                dualgrid.DynamicGrid(p, seed=1)

    def test_presets_differ_in_the_switches_only(self):
        # params.hpp: "paper" sets every switch to its literal reading; "dualgrid" is the
        # recommendation, "default" the struct defaults (equal today); only switches differ.
        self.assertEqual(sorted(dualgrid.preset_names()), ["default", "dualgrid", "paper"])
        paper = dualgrid.preset("paper").to_dict()
        ours = dualgrid.preset("dualgrid").to_dict()
        default = dualgrid.preset("default").to_dict()
        self.assertEqual(default, dualgrid.FilterParams().to_dict())
        self.assertEqual(ours, default)
        differing = sorted(k for k in paper if paper[k] != ours[k])
        self.assertEqual(differing, sorted(SWITCHES))
        self.assertEqual(
            {k: paper[k] for k in SWITCHES}, {
                "birth_velocity": "uniform",
                "zero_likelihood": "literal",
                "velocity_likelihood": "vector",
                "normalisation": "literal"
            })
        with self.assertRaisesRegex(ValueError, "preset: unknown name 'papr' .*paper"):
            dualgrid.preset("papr")

    def test_copy_equality_and_pickle(self):
        p = dualgrid.FilterParams(num_particles=123, mode="position")
        for q in (copy.copy(p), copy.deepcopy(p), pickle.loads(pickle.dumps(p))):
            self.assertEqual(q, p)
            self.assertIsNot(q, p)
        q = copy.copy(p)
        q.num_particles = 7
        self.assertNotEqual(q, p)
        self.assertEqual(p.num_particles, 123)
        self.assertIn("num_particles=123", repr(p))

    def test_memory_bytes(self):
        p = dualgrid.FilterParams()
        # FilterParams::MemoryBytes: 94 B per cell (the grid's 81 and its own MeasurementGrid's
        # 13), 72 B per particle (with the resampling's owner index) and 36 B per new-born one
        # (float state, docs/algorithm.md).
        self.assertAlmostEqual(p.memory_bytes(), 94.0 * 400 * 50 + 72.0 * 10000 + 36.0 * 1000)


class SensorParamsTest(unittest.TestCase):

    def test_default_rig(self):
        rig = dualgrid.default_rig(4.5, 1.8)
        self.assertEqual([s.name for s in rig],
                         ["front_left", "front_right", "rear_left", "rear_right", "front"])
        fl = rig[0]
        self.assertAlmostEqual(fl.mount[0], 0.3 * 4.5)
        self.assertAlmostEqual(fl.mount[1], 0.9)
        self.assertAlmostEqual(fl.mount[2], math.radians(45.0))
        self.assertEqual(rig[4].mount, (2.25, 0.0, 0.0))
        self.assertAlmostEqual(rig[4].fov, math.radians(20.0))
        for s in rig:
            self.assertTrue(s.is_valid(), s.name)
        clean = dualgrid.default_rig(4.5, 1.8, accuracy="clean")
        self.assertEqual(clean[0].off_boresight, [])
        self.assertAlmostEqual(clean[0].range_accuracy, 0.05 * clean[0].range_resolution)
        with self.assertRaisesRegex(ValueError, "accuracy: unknown value 'exact'"):
            dualgrid.default_rig(4.5, 1.8, accuracy="exact")
        with self.assertRaisesRegex(ValueError, "ego_length and ego_width must be positive"):
            dualgrid.default_rig(0.0, 1.8)

    def test_named_defaults(self):
        self.assertEqual(dualgrid.default_short_range_radar().name, "short_range")
        lr = dualgrid.default_long_range_radar()
        self.assertEqual((lr.name, lr.max_range), ("long_range", 174.0))

    def test_fields_and_validation(self):
        s = dualgrid.SensorParams(name="side", mount=(0.0, 0.9, math.pi / 2), max_range=50.0)
        self.assertEqual(s.mount, (0.0, 0.9, math.pi / 2))
        self.assertEqual(s.max_range, 50.0)
        self.assertIsNone(s.validate())
        s.max_range = 0.1  # below min_range
        self.assertFalse(s.is_valid())
        with self.assertRaisesRegex(ValueError, "SensorParams 'side': max_range"):
            s.validate()
        with self.assertRaisesRegex(ValueError, r"mount: expected \(x, y, yaw\)"):
            s.mount = (1.0, 2.0)
        with self.assertRaisesRegex(ValueError, "radar sensor 0 \\('side'\\): max_range"):
            dualgrid.RadarModel([s])
        self.assertEqual(pickle.loads(pickle.dumps(s)), s)

    def test_model_options(self):
        o = dualgrid.ModelOptions(noise=False)
        d = o.to_dict()
        self.assertEqual(d["multipath"], dualgrid.MultipathParams().to_dict())
        del d["multipath"]
        self.assertEqual(d, {"noise": False, "false_alarms": True, "occlusion": True})

    def test_multipath_options(self):
        o = dualgrid.ModelOptions()
        self.assertFalse(o.multipath.enabled)
        o.multipath.enabled = True  # in place
        o.multipath.max_bounces = 2
        self.assertTrue(o.to_dict()["multipath"]["enabled"])
        back = pickle.loads(pickle.dumps(o))
        self.assertEqual(back, o)
        self.assertEqual(back.multipath.max_bounces, 2)
        self.assertEqual(dualgrid.ModelOptions(multipath={"enabled": True}).multipath,
                         dualgrid.MultipathParams(enabled=True))
        with self.assertRaisesRegex(TypeError, "multipath: expected a MultipathParams"):
            dualgrid.ModelOptions(multipath=3)
        bad = dualgrid.MultipathParams(enabled=True, max_bounces=7)
        self.assertFalse(bad.is_valid())
        with self.assertRaisesRegex(ValueError, "MultipathParams: max_bounces"):
            bad.validate()
        with self.assertRaisesRegex(ValueError, "multipath.max_bounces"):
            dualgrid.RadarModel(dualgrid.default_rig(4.5, 1.8),
                                options=dualgrid.ModelOptions(multipath=bad))


if __name__ == "__main__":
    unittest.main()
