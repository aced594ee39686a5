"""The Python module bounded exactly like the command line (issue 42): thread counts (4 per core,
as --threads), the grid's cell count, a coverage's half_fov, scenario numbers through --set's
validated ranges. Every case raises ValueError naming the argument or key; none may end the
interpreter (all cases run in this one process, so a crash fails the whole script).

Needs DUALGRID_SOURCE_DIR; run against the installed package (tests/python)."""

import math
import os
import unittest

import numpy as np

import dualgrid

SCENARIO = os.path.join(os.environ.get("DUALGRID_SOURCE_DIR", "."), "scenarios", "simple_road.yaml")
COVERAGE = [0.0, 0.0, 0.0, math.radians(60.0), 0.3, 80.0]


def max_threads():
    # The command line's bound: 4 threads per core this process may use.
    return 4 * len(os.sched_getaffinity(0))


class ThreadBoundTest(unittest.TestCase):

    def tearDown(self):
        dualgrid.set_num_threads(0)

    def test_set_num_threads(self):
        for n in (-1, max_threads() + 1, 100000, 2**31 - 1):
            with self.assertRaisesRegex(ValueError, r"set_num_threads: n must be >= 0 and <= %d "
                                        r"\(4 per core, as --threads\), got %d" % (max_threads(), n)):
                dualgrid.set_num_threads(n)
        dualgrid.set_num_threads(max_threads())  # the bound itself is accepted
        self.assertEqual(dualgrid.get_num_threads(), max_threads())

    def test_runs(self):
        for make in (lambda n: dualgrid.run_scenario(SCENARIO, duration=0.1, threads=n),
                     lambda n: dualgrid.CoSimulation(SCENARIO, duration=0.1, threads=n)):
            with self.assertRaisesRegex(ValueError, "threads must be >= 0 and <= %d" % max_threads()):
                make(100000)


class GridBoundTest(unittest.TestCase):

    def test_cell_count(self):
        cases = [(dict(width_y=1e300), "width_y = 1e\\+300"),
                 (dict(length_x=1e300), "length_x = 1e\\+300"),
                 (dict(resolution=1e-9), "length_x"),
                 (dict(length_x=3e4, width_y=3e4, resolution=1.0), "length_x/width_y/resolution")]
        for kw, key in cases:
            with self.subTest(**kw):
                with self.assertRaisesRegex(ValueError, key + ".*at most 200000000 cells"):
                    dualgrid.DynamicGrid(dualgrid.FilterParams(**kw), seed=1)

    def test_memory(self):
        # More particles than 80 % of this machine's memory holds (memory_bytes() is the layout's
        # estimate, within 5 % of the allocation): refused before anything is allocated, as the
        # command line refuses it; the largest count the int field holds is far beyond any machine
        # this suite runs on (2^31 - 1 particles ~ 146 GB).
        total = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
        huge = dualgrid.FilterParams(num_particles=2**31 - 1)
        self.assertGreater(huge.memory_bytes(), 0.8 * total)
        with self.assertRaisesRegex(ValueError, r"num_particles = 2147483647.*more than 80 % of"):
            dualgrid.DynamicGrid(huge, seed=1)
        small = dualgrid.FilterParams(num_particles=1000, num_birth=100)
        self.assertLess(small.memory_bytes(), 0.8 * total)
        dualgrid.DynamicGrid(small, seed=1)  # an ordinary size is accepted

    def test_half_fov(self):
        grid = dualgrid.DynamicGrid(dualgrid.FilterParams(length_x=20.0, width_y=10.0,
                                                          num_particles=1000, num_birth=100), seed=1)
        for half_fov in (1e6, math.pi + 1e-9, -0.1):
            cov = np.array([COVERAGE[:3] + [half_fov] + COVERAGE[4:]])
            with self.assertRaisesRegex(ValueError, r"coverage: row 0 .*0 <= half_fov <= pi"):
                grid.update((0.0, 0.0, 0.0), (0.0, 0.0), np.zeros((0, 6)), cov, dt=0.05)
        cov = np.array([COVERAGE[:3] + [math.pi] + COVERAGE[4:]])  # a full circle: accepted
        grid.update((0.0, 0.0, 0.0), (0.0, 0.0), np.zeros((0, 6)), cov, dt=0.05)

    def test_crowded_update_finishes(self):
        # 10^5 detections in a 20 m x 10 m grid (500 per square metre): the Doppler fit looks at a
        # bounded number of candidates per detection (docs/algorithm.md, step 4a), so this takes
        # about a second, not minutes; the result stays a valid grid.
        rng = np.random.default_rng(1)
        n = 100000
        d = np.column_stack([rng.uniform(-10, 10, n), rng.uniform(-5, 5, n), rng.normal(0, 1, n),
                             rng.normal(0, 1, n), np.zeros(n), np.zeros(n)])
        grid = dualgrid.DynamicGrid(dualgrid.FilterParams(length_x=20.0, width_y=10.0,
                                                          num_particles=20000, num_birth=2000),
                                    seed=1)
        grid.update((0.0, 0.0, 0.0), (0.0, 0.0), d, np.array([COVERAGE]), dt=0.05)
        masses = grid.masses()
        for name in ("free", "static", "dynamic"):
            self.assertTrue(np.all(np.isfinite(masses[name])))
            self.assertTrue(np.all((masses[name] >= 0.0) & (masses[name] <= 1.0)))


class ScenarioNumberTest(unittest.TestCase):

    def test_set_keys(self):
        cases = [("seed=9007199254740993", "key 'seed' expected a whole number in \\[0, 9007199254740991\\]"),
                 ("vehicle_types.car.vclass=spaceship", "vehicle_types.car.vclass.*rail_fast"),
                 ("vehicle_types.car.length=1e9", "vehicle_types.car.length.*\\(0, 30\\] m"),
                 ("filter.width_y=1e300", "filter.width_y.*at most 200000000 cells")]
        for override, message in cases:
            with self.subTest(override=override):
                with self.assertRaisesRegex(ValueError, message):
                    dualgrid.CoSimulation(SCENARIO, duration=0.1, overrides=[override])


if __name__ == "__main__":
    unittest.main()
