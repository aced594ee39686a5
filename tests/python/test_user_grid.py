"""Clustering and scoring on a grid of one's own (python/src/eval_bindings.cpp): classify_cells,
score_cells, dynamic_particles, cluster_particles and associate give what the co-simulation's
scorer gives on the same grid (checked against a stepped CoSimulation's StepGrid), and refuse
arrays of the wrong shape, NaN and wrong types with a message. Multipath ghosts from the bound
radar model. Run against the installed package (tests/python)."""

import math
import os
import unittest

import numpy as np

import dualgrid

SCENARIO = os.path.join(os.environ.get("DUALGRID_SOURCE_DIR", "."), "scenarios", "simple_road.yaml")


def tracked_grid(cycles=40):
    """A car crossing 20 m ahead at 10 m/s, exact detections on its near face (as test_tracking)."""
    params = dualgrid.preset("dualgrid")
    params.num_particles, params.num_birth = 20000, 2000
    grid = dualgrid.DynamicGrid(params, seed=1)
    sensor = np.array([2.0, 0.0])
    cov = [[*sensor, 0.0, math.radians(10.0), 0.5, 200.0]]
    for k in range(cycles):
        rear = 20.0 + 10.0 * k * 0.05
        rows = []
        for y in np.arange(-0.8, 0.81, 0.4):
            p = np.array([rear, y])
            los = (p - sensor) / np.linalg.norm(p - sensor)
            rows.append([*p, *(np.dot([10.0, 0.0], los) * los), *sensor])
        grid.update(ego_pose=(0.0, 0.0, 0.0), detections=np.array(rows), coverage=cov, dt=0.05)
    return grid, rear


class OwnGridTest(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.grid, cls.rear = tracked_grid()

    def test_classify_matches_the_rule(self):
        m = self.grid.masses()
        c = dualgrid.classify_cells(m)
        stacked = np.stack([m["free"], m["static"], m["dynamic"]], axis=-1)
        self.assertTrue(np.array_equal(c, dualgrid.classify_cells(stacked)))
        self.assertEqual(c.shape, m["dynamic"].shape)
        self.assertTrue(np.array_equal(c == 2, m["dynamic"] > 0.6))
        self.assertTrue(np.array_equal((c == 1), (m["dynamic"] <= 0.6) & (m["static"] > 0.6)))
        self.assertGreater(np.count_nonzero(c == 2), 0)

    def test_cluster_on_the_car(self):
        parts = dualgrid.dynamic_particles(self.grid)
        self.assertGreater(len(parts["x"]), 50)
        clusters = dualgrid.cluster_particles(parts)
        self.assertEqual(len(clusters["x"]), 1)
        # The cluster sits on the car's rear and moves at its 10 m/s (bounds: a few cells).
        self.assertLess(abs(clusters["x"][0] - self.rear), 2.0)
        self.assertLess(abs(clusters["y"][0]), 1.0)
        self.assertLess(abs(clusters["vx"][0] - 10.0), 2.0)
        self.assertAlmostEqual(clusters["weight"][0],
                               parts["weight"][(parts["x"] >= clusters["min_x"][0])
                                               & (parts["x"] <= clusters["max_x"][0])].sum(),
                               delta=1e-6 * clusters["weight"][0] + 1e-9)
        # Associated with a box on the car, and false with the box moved away.
        car = [dict(x=self.rear + 2.25, y=0.0, yaw=0.0, length=4.5, width=1.8, vx=10.0)]
        a = dualgrid.associate(clusters, car)
        self.assertEqual((a["matched"], a["false"]), (1, 0))
        self.assertEqual(a["object_of_cluster"].tolist(), [0])
        far = [dict(car[0], x=self.rear + 30.0)]
        self.assertEqual(dualgrid.associate(clusters, far)["false"], 1)

    def test_score_cells(self):
        m = self.grid.masses()
        pred = dualgrid.classify_cells(m)
        truth = np.zeros_like(pred)
        truth[pred == 2] = 2
        s = dualgrid.score_cells(pred, truth, m["observed"])
        self.assertEqual(s["cells"], int(m["observed"].sum()))
        self.assertEqual(s["dynamic_recall"], 1.0)
        self.assertEqual(s["dynamic_precision"], 1.0)
        self.assertEqual(sum(map(sum, s["confusion_truth_by_predicted"])), s["cells"])

    def test_wrong_shapes_nan_and_types(self):
        m = self.grid.masses()
        stacked = np.stack([m["free"], m["static"], m["dynamic"]], axis=-1)
        with self.assertRaisesRegex(ValueError, r"masses: expected shape \(ny, nx, 3\).*\(50, 400, 2\)"):
            dualgrid.classify_cells(stacked[..., :2])
        with self.assertRaisesRegex(ValueError, "masses: expected shape"):
            dualgrid.classify_cells(np.zeros(5))
        bad = stacked.copy()
        bad[3, 4, 1] = np.nan
        with self.assertRaisesRegex(ValueError, "masses: value .* is not finite"):
            dualgrid.classify_cells(bad)
        with self.assertRaisesRegex(ValueError, "masses: the dict has no 'static'"):
            dualgrid.classify_cells({"free": m["free"], "dynamic": m["dynamic"]})
        with self.assertRaisesRegex(ValueError, "threshold"):
            dualgrid.classify_cells(stacked, threshold=math.nan)
        with self.assertRaises(TypeError):
            dualgrid.classify_cells(stacked, threshold="high")
        pred = dualgrid.classify_cells(stacked)
        with self.assertRaisesRegex(ValueError, "truth: shape .* differs"):
            dualgrid.score_cells(pred, np.zeros_like(pred)[:10])
        with self.assertRaisesRegex(ValueError, "truth: value 3 .* is not a class"):
            dualgrid.score_cells(pred, pred)  # unknown (3) is not a truth class
        with self.assertRaisesRegex(ValueError, "classes: expected the grid's shape"):
            dualgrid.dynamic_particles(self.grid, pred.T)
        with self.assertRaises(TypeError):
            dualgrid.dynamic_particles("grid")
        with self.assertRaisesRegex(ValueError, "particles: .*weight"):
            dualgrid.cluster_particles({"x": [1.0], "y": [1.0], "vx": [0.0], "vy": [0.0]})
        with self.assertRaisesRegex(ValueError, "particles: .*not finite|finite"):
            dualgrid.cluster_particles({"x": [np.nan], "y": [1.0], "vx": [0.0], "vy": [0.0],
                                        "weight": [1.0]})
        with self.assertRaisesRegex(ValueError, "cluster_particles: .*eps"):
            dualgrid.cluster_particles({"x": [], "y": [], "vx": [], "vy": [], "weight": []},
                                       eps=-1.0)
        # An empty grid has no particles.
        self.assertEqual(len(dualgrid.dynamic_particles(dualgrid.DynamicGrid())["x"]), 0)


class AgainstTheScorerTest(unittest.TestCase):
    """A stepped co-simulation's grid scored by hand gives the step's own scores."""

    def test_step_grid_rescored(self):
        sim = dualgrid.CoSimulation(SCENARIO, modes=["dual"], seed=3, duration=3.0)
        checked = 0
        for step in sim:
            g = step.grids["dual"]
            self.assertTrue(np.array_equal(dualgrid.classify_cells(g.masses), g.classes))
            s = dualgrid.score_cells(g.classes, g.truth_classes, g.observed)
            self.assertEqual(s["confusion_truth_by_predicted"], g.scores["cells"].tolist())
            if len(g.clusters):
                truth = step.truth
                objs = [dict(x=t["x"], y=t["y"], yaw=t["yaw"], length=t["length"],
                             width=t["width"]) for t in truth]
                a = dualgrid.associate(g.clusters, objs)
                self.assertEqual(a["role"].tolist(), g.clusters["role"].tolist())
                ids = [int(truth["id"][o]) if o >= 0 else -1 for o in a["object_of_cluster"]]
                self.assertEqual(ids, g.clusters["object"].tolist())
                checked += 1
        self.assertGreater(checked, 10)


class MultipathTest(unittest.TestCase):

    def test_ghosts_only_with_multipath(self):
        ego = dualgrid.EgoMotion(pose=(0, 0, 0), velocity=(20, 0), length=4.5, width=1.8)
        scene = {"targets": [dict(id=1, x=25.0, y=-3.5, length=12.0, width=2.5, vx=15.0),
                             dict(id=2, x=40.0, y=3.5, length=4.5, width=1.8, vx=25.0)],
                 "polylines": [{"id": 10, "points": np.array([[-50, 6.0], [150, 6.0]])}]}
        counts = {}
        for on in (False, True):
            opts = dualgrid.ModelOptions(multipath=dualgrid.MultipathParams(enabled=on))
            radar = dualgrid.RadarModel(dualgrid.default_rig(4.5, 1.8), options=opts, seed=1)
            ghosts = 0
            for k in range(20):
                d = radar.scan(ego, scene, step=k, time=k * 0.05)
                g = d["path"] > 0
                ghosts += int(g.sum())
                # A ghost names its mirror and its object, never itself as a source.
                self.assertTrue(np.all(d["bounces"][g] >= 2))
                self.assertTrue(np.all(np.isin(d["ghost_of"][g], [1, 2])))
                self.assertTrue(np.all(np.isin(d["reflector_id"][g], [1, 10])))
                self.assertTrue(np.all(d["source_id"][g] == -1))
            counts[on] = ghosts
        self.assertEqual(counts[False], 0)
        self.assertGreater(counts[True], 0)


if __name__ == "__main__":
    unittest.main()
