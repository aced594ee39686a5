"""DynamicGrid's Python interface: input forms and their errors, output shapes, copies, geometry
(python/src/filter_bindings.cpp)."""

import math
import threading
import unittest

import numpy as np

import dualgrid

DT = 0.05


def small_params(**kw):
    # 40 m x 20 m at 0.5 m, 4000 particles: fast, same code paths as the paper's size.
    base = dict(length_x=40.0, width_y=20.0, num_particles=4000, num_birth=400)
    base.update(kw)
    return dualgrid.FilterParams(**base)


def scene_inputs(k):
    """Cycle k of a small synthetic scene: a car 12 m ahead receding at 5 m/s seen by one forward
    sensor at the origin (exact eq. (1) detections on its rear face) plus a static return."""
    sensor = np.array([2.0, 0.0])
    rear_x = 12.0 + 5.0 * k * DT
    rows = []
    for y in (-0.6, -0.3, 0.0, 0.3, 0.6):
        p = np.array([rear_x, 1.0 + y])
        los = (p - sensor) / np.linalg.norm(p - sensor)
        vr = np.dot([5.0, 0.0], los) * los
        rows.append([p[0], p[1], vr[0], vr[1], sensor[0], sensor[1]])
    rows.append([8.0, -5.0, 0.0, 0.0, sensor[0], sensor[1]])
    detections = np.array(rows)
    coverage = np.array([[sensor[0], sensor[1], 0.0, math.radians(60.0), 0.3, 80.0]])
    return detections, coverage


def run(grid, cycles, form=lambda d, c: (d, c)):
    for k in range(cycles):
        d, c = form(*scene_inputs(k))
        grid.update((0.0, 0.0, 0.0), (0.0, 0.0), d, c, dt=DT)


class InputTest(unittest.TestCase):

    def setUp(self):
        self.grid = dualgrid.DynamicGrid(small_params(), seed=3)
        self.det, self.cov = scene_inputs(0)

    def assert_value_error(self, pattern, **kw):
        args = dict(ego_pose=(0.0, 0.0, 0.0), ego_velocity=(0.0, 0.0), detections=self.det,
                    coverage=self.cov, dt=DT)
        args.update(kw)
        with self.assertRaisesRegex(ValueError, pattern):
            self.grid.update(**args)
        self.assertEqual(self.grid.step, 0, "a refused update must not change the grid")

    def test_bad_shapes_name_the_argument(self):
        self.assert_value_error(r"detections: expected a float array of shape \(N, 6\) with "
                                r"columns \[x, y, v_rx, v_ry, sensor_x, sensor_y\], got shape "
                                r"\(6, 5\)", detections=self.det[:, :5])
        self.assert_value_error(r"detections: .*got shape \(36,\)", detections=self.det.ravel())
        self.assert_value_error(r"coverage: expected a float array of shape \(N, 6\) with columns "
                                r"\[origin_x, origin_y, boresight, half_fov, min_range, "
                                r"max_range\], got shape \(1, 5\)", coverage=self.cov[:, :5])
        self.assert_value_error(r"ego_pose: expected \(x, y, yaw\) \[m, m, rad\]",
                                ego_pose=(0.0, 0.0))
        self.assert_value_error(r"ego_velocity: expected \(x, y\) \[m/s\]",
                                ego_velocity=(1.0, 2.0, 3.0))
        self.assert_value_error("detections: cannot convert", detections=[["a"] * 6])

    def test_bad_values_name_the_argument(self):
        d = self.det.copy()
        d[2, 3] = np.nan
        self.assert_value_error("detections: row 2, column 'v_ry' is not finite", detections=d)
        c = self.cov.copy()
        c[0, 5] = 0.1  # max_range < min_range
        self.assert_value_error("coverage: row 0 .*needs", coverage=c)
        self.assert_value_error(r"dt: expected a finite cycle length >= 0 \[s\]", dt=-0.1)
        self.assert_value_error("dt: expected a finite", dt=math.inf)
        self.assert_value_error("ego_pose: expected finite", ego_pose=(0.0, math.nan, 0.0))

    def test_named_forms_missing_columns(self):
        cols = {n: self.det[:, i] for i, n in enumerate(dualgrid.MEASUREMENT_COLUMNS)}
        del cols["v_rx"]
        self.assert_value_error(r"detections: missing column 'v_rx'", detections=cols)
        records = [dict(zip(dualgrid.MEASUREMENT_COLUMNS, row)) for row in self.det]
        records[1]["vrx"] = 0.0
        self.assert_value_error(r"detections\[1\]: unknown key 'vrx'", detections=records)
        cols = {n: self.det[:, i] for i, n in enumerate(dualgrid.MEASUREMENT_COLUMNS)}
        cols["x"] = cols["x"][:3]
        self.assert_value_error("detections: columns of different lengths", detections=cols)

    def test_empty_inputs(self):
        for empty in (None, [], np.empty((0, 6)), np.empty((0,))):
            g = dualgrid.DynamicGrid(small_params(), seed=3)
            g.update((0.0, 0.0, 0.0), detections=empty, coverage=empty, dt=DT)
            self.assertEqual(g.step, 1)
            self.assertFalse(g.masses()["observed"].any())

    def test_all_forms_give_identical_grids(self):
        """Array, dict of columns, structured array, list of dicts and pandas-like mapping feed
        the same doubles: the grids agree bit for bit."""

        def as_dict(d, c):
            return ({n: d[:, i] for i, n in enumerate(dualgrid.MEASUREMENT_COLUMNS)},
                    {n: c[:, i] for i, n in enumerate(dualgrid.COVERAGE_COLUMNS)})

        def as_structured(d, c):
            def struct(a, names):
                s = np.zeros(a.shape[0], dtype=[(n, "f8") for n in names])
                for i, n in enumerate(names):
                    s[n] = a[:, i]
                return s
            return (struct(d, dualgrid.MEASUREMENT_COLUMNS),
                    struct(c, dualgrid.COVERAGE_COLUMNS))

        def as_records(d, c):
            return ([dict(zip(dualgrid.MEASUREMENT_COLUMNS, r)) for r in d],
                    [dict(zip(dualgrid.COVERAGE_COLUMNS, r)) for r in c])

        def as_lists_and_fortran(d, c):
            return d.tolist(), np.asfortranarray(c)

        reference = dualgrid.DynamicGrid(small_params(), seed=3)
        run(reference, 8)
        ref = reference.masses()
        ref_p = reference.particles()
        for form in (as_dict, as_structured, as_records, as_lists_and_fortran):
            g = dualgrid.DynamicGrid(small_params(), seed=3)
            run(g, 8, form)
            for k, v in g.masses().items():
                np.testing.assert_array_equal(v, ref[k], err_msg=f"{form.__name__} {k}")
            for k, v in g.particles().items():
                np.testing.assert_array_equal(v, ref_p[k], err_msg=f"{form.__name__} {k}")

    def test_pandas_dataframe_input(self):
        import pandas as pd
        g1 = dualgrid.DynamicGrid(small_params(), seed=3)
        g2 = dualgrid.DynamicGrid(small_params(), seed=3)
        d, c = scene_inputs(0)
        g1.update((0.0, 0.0, 0.0), detections=d, coverage=c, dt=DT)
        g2.update((0.0, 0.0, 0.0),
                  detections=pd.DataFrame(d, columns=dualgrid.MEASUREMENT_COLUMNS).assign(
                      extra=1.0),
                  coverage=pd.DataFrame(c, columns=dualgrid.COVERAGE_COLUMNS), dt=DT)
        np.testing.assert_array_equal(g1.masses()["dynamic"], g2.masses()["dynamic"])


class OutputTest(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.params = small_params()
        cls.grid = dualgrid.DynamicGrid(cls.params, seed=5)
        run(cls.grid, 20)

    def test_masses(self):
        g = self.grid
        m = g.masses()
        self.assertEqual(set(m), {"free", "static", "dynamic", "unknown", "observed"})
        for k in ("free", "static", "dynamic", "unknown"):
            self.assertEqual(m[k].shape, (g.cells_y, g.cells_x))
            self.assertEqual(m[k].dtype, np.float32)
            self.assertTrue(np.all((m[k] >= 0) & (m[k] <= 1)), k)
        self.assertEqual(m["observed"].dtype, bool)
        total = m["free"] + m["static"] + m["dynamic"] + m["unknown"]
        np.testing.assert_allclose(total, 1.0, atol=1e-5)
        self.assertTrue(m["observed"].any() and not m["observed"].all())
        # Masses agree with cell() (double precision) to float32 rounding.
        ix, iy = g.cell_of(14.0, 1.0)
        c = g.cell(ix, iy)
        self.assertAlmostEqual(c["dynamic"], m["dynamic"][iy, ix], places=6)
        self.assertAlmostEqual(c["free"], m["free"][iy, ix], places=6)
        self.assertEqual(c["observed"], m["observed"][iy, ix])

    def test_mean_velocities(self):
        g = self.grid
        v = g.mean_velocities()
        self.assertEqual(v.shape, (g.cells_y, g.cells_x, 2))
        cov = g.velocity_covariances()
        self.assertEqual(cov.shape, (g.cells_y, g.cells_x, 2, 2))
        ix, iy = np.unravel_index(np.argmax(g.masses()["dynamic"]), (g.cells_y, g.cells_x))[::-1]
        c = g.cell(int(ix), int(iy))
        self.assertEqual(tuple(v[iy, ix]), c["mean_velocity"])
        self.assertEqual(tuple(map(tuple, cov[iy, ix])), c["velocity_cov"])

    def test_particles(self):
        g = self.grid
        p = g.particles()
        self.assertEqual(set(p), {"x", "y", "vx", "vy", "w_position", "w_velocity", "weight"})
        for k, a in p.items():
            self.assertEqual(a.shape, (self.params.num_particles,), k)
            self.assertTrue(np.all(np.isfinite(a)), k)
        self.assertEqual(p["x"].dtype, np.float64)
        self.assertEqual(p["vx"].dtype, np.float32)
        self.assertTrue(np.all(p["weight"] >= 0))
        # After resampling all weights are equal (total dynamic mass / count).
        self.assertTrue(np.all(p["weight"] == p["weight"][0]))
        w = g.weighted_particles()
        n = g.num_weighted_particles()
        self.assertGreater(n, 0)
        for k, a in w.items():
            self.assertEqual(a.shape, (n,), k)
            self.assertTrue(np.all(np.isfinite(a)), k)
        self.assertIsNone(g.check_invariants())

    def test_geometry(self):
        g = self.grid
        self.assertEqual((g.cells_x, g.cells_y, g.resolution), (80, 40, 0.5))
        self.assertEqual(g.step, 20)
        self.assertTrue(g.initialized)
        self.assertEqual(g.extent, (-20.0, 20.0, -10.0, 10.0))
        self.assertEqual(g.cell_center(0, 0), (-19.75, -9.75))
        for ix, iy in ((0, 0), (79, 39), (13, 27)):
            self.assertEqual(g.cell_of(*g.cell_center(ix, iy)), (ix, iy))
        self.assertIsNone(g.cell_of(20.0, 0.0))  # the upper edge is outside
        self.assertIsNone(g.cell_of(0.0, -10.01))
        self.assertIsNone(g.cell_of(math.nan, 0.0))
        with self.assertRaises(IndexError):
            g.cell_center(80, 0)
        with self.assertRaises(IndexError):
            g.cell(0, -1)
        self.assertEqual(g.params, self.params)

    def test_before_first_update(self):
        g = dualgrid.DynamicGrid(small_params(), seed=1)
        self.assertFalse(g.initialized)
        self.assertIsNone(g.extent)
        self.assertIsNone(g.cell_of(0.0, 0.0))
        self.assertIsNone(g.cell_center(0, 0))
        self.assertEqual(g.num_weighted_particles(), 0)
        self.assertEqual(g.masses()["dynamic"].shape, (40, 80))

    def test_outputs_are_copies(self):
        g = dualgrid.DynamicGrid(small_params(), seed=5)
        run(g, 3)
        m = g.masses()
        p = g.particles()
        before = m["dynamic"].copy(), p["x"].copy()
        m["dynamic"][:] = 7.0
        p["x"][:] = 7.0
        np.testing.assert_array_equal(g.masses()["dynamic"], before[0])
        np.testing.assert_array_equal(g.particles()["x"], before[1])
        run(g, 1)  # later updates do not change arrays already returned
        self.assertTrue(np.all(m["dynamic"] == 7.0))
        del g
        self.assertTrue(np.all(p["x"] == 7.0))  # still valid after the grid is gone


class ThreadTest(unittest.TestCase):

    def test_results_do_not_depend_on_threads_or_concurrency(self):
        """Two grids updated concurrently from Python threads (update() releases the GIL), with
        one and two OpenMP threads, give the masses of a sequential run bit for bit."""
        reference = dualgrid.DynamicGrid(small_params(), seed=9)
        run(reference, 10)
        ref = reference.masses()["dynamic"]
        old = dualgrid.get_num_threads()
        try:
            for n in (1, 2):
                dualgrid.set_num_threads(n)
                self.assertEqual(dualgrid.get_num_threads(), n)
                grids = [dualgrid.DynamicGrid(small_params(), seed=9) for _ in range(2)]
                threads = [threading.Thread(target=run, args=(g, 10)) for g in grids]
                for t in threads:
                    t.start()
                for t in threads:
                    t.join()
                for g in grids:
                    np.testing.assert_array_equal(g.masses()["dynamic"], ref)
        finally:
            dualgrid.set_num_threads(0)
        self.assertEqual(dualgrid.get_num_threads(), old)
        with self.assertRaisesRegex(ValueError, "set_num_threads: n must be >= 0"):
            dualgrid.set_num_threads(-1)

    def test_one_grid_shared_by_threads(self):
        """Readers in other threads while one thread updates: serialised by the grid's lock, so
        every read sees a whole cycle (the invariants hold) and nothing crashes."""
        g = dualgrid.DynamicGrid(small_params(), seed=2)
        run(g, 1)
        errors = []
        done = threading.Event()

        def reader():
            while not done.is_set():
                if g.check_invariants() is not None:
                    errors.append(g.check_invariants())
                g.particles()
                g.masses()

        t = threading.Thread(target=reader)
        t.start()
        try:
            run(g, 15)
        finally:
            done.set()
            t.join()
        self.assertEqual(errors, [])



class ReframeTest(unittest.TestCase):

    def test_reframe_turns_particles_exactly_and_recentres(self):
        grid = dualgrid.DynamicGrid(small_params(), seed=3)
        run(grid, 10)
        before = grid.particles()
        a = 0.4
        c, s = math.cos(a), math.sin(a)
        grid.reframe(a, (0.0, 0.0))
        after = grid.particles()
        # Positions are float grid-local metres (docs/algorithm.md, "Float state"): the turned
        # position is rounded once to a float of magnitude M <= the grid's diagonal [m], so
        # |error| <= 2^-24 M, plus the double arithmetic's (~1e-13 m).
        p = small_params()
        tol = 2.0**-24 * math.hypot(p.length_x, p.width_y) + 1e-12
        np.testing.assert_allclose(after["x"], c * before["x"] + s * before["y"], rtol=0, atol=tol)
        np.testing.assert_allclose(after["y"], -s * before["x"] + c * before["y"], rtol=0, atol=tol)
        np.testing.assert_allclose(after["vx"], c * before["vx"] + s * before["vy"], atol=1e-4)
        np.testing.assert_array_equal(after["weight"], before["weight"])
        # The next cycle, in the turned frame, keeps the grid's invariants.
        grid.update((0.0, 0.0, -a), (0.0, 0.0), None, None, dt=DT)
        self.assertIsNone(grid.check_invariants())

    def test_reframe_refuses_non_finite_input(self):
        grid = dualgrid.DynamicGrid(small_params(), seed=3)
        with self.assertRaisesRegex(ValueError, "angle"):
            grid.reframe(float("nan"), (0.0, 0.0))
        with self.assertRaisesRegex(ValueError, "ego_position"):
            grid.reframe(0.1, (0.0, float("inf")))


if __name__ == "__main__":
    unittest.main()
