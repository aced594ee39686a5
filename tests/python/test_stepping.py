"""dualgrid.CoSimulation (python/src/stepping_bindings.cpp) stepped one step at a time against the
command line and run_scenario: the same scenario and seed give metrics.json, every step's
clusters (clusters.csv) and run_scenario's dict; each step's grids, detections, truth and scores
are consistent with each other and with the run's metrics.

Needs DUALGRID_EXE (the dualgrid program); run against the installed package (tests/python)."""

import csv
import json
import os
import subprocess
import tempfile
import unittest

import numpy as np
import pandas as pd

import dualgrid

SCENARIO = os.path.join(os.environ.get("DUALGRID_SOURCE_DIR", "."), "scenarios", "simple_road.yaml")
DURATION = 4.0
SEED = 3
OVERRIDES = ["filter.preset=paper"]


def fnv1a64(data):
    """summary.json's digest of a file's bytes (tools/src/output.cpp, OutputDigests)."""
    h = 14695981039346656037
    for b in data:
        h = ((h ^ b) * 1099511628211) & 0xFFFFFFFFFFFFFFFF
    return f"{h:016x}"


class SteppingTest(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        out = os.path.join(cls.tmp.name, "cli")
        cls.cli_dir = out
        subprocess.run([os.environ["DUALGRID_EXE"], "run", SCENARIO, "--out", out, "--seed",
                        str(SEED), "--duration", str(DURATION), "--no-figures", "-q",
                        "--set", OVERRIDES[0]], check=True)
        with open(os.path.join(out, "metrics.json")) as f:
            cls.cli = json.load(f)
        with open(os.path.join(out, "clusters.csv")) as f:
            cls.cli_clusters = list(csv.DictReader(f))
        sim = dualgrid.CoSimulation(SCENARIO, seed=SEED, duration=DURATION, overrides=OVERRIDES,
                                    threads=2)
        cls.steps = list(sim)
        cls.results = sim.results()
        cls.sim = sim
        cls.via_run_scenario = dualgrid.run_scenario(SCENARIO, seed=SEED, duration=DURATION,
                                        overrides=OVERRIDES, threads=1)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_results_equal_the_cli_and_run_scenario(self):
        r = self.results
        self.assertEqual(self.sim.state, "ended")
        self.assertTrue(r["complete"])
        self.assertEqual(r["steps"], self.cli["steps"])
        self.assertEqual(len(self.steps), r["steps"])
        for mode, m in self.cli["modes"].items():
            self.assertEqual(r["metrics"][mode], m, mode)
        self.assertGreater(r["metrics"]["dual"]["matches"], 0)
        self.assertEqual(r["object_names"], self.cli["object_names"])
        # run_scenario's dict, key by key (numpy columns element by element).
        self.assertEqual(set(r), set(self.via_run_scenario))
        for k in r:
            if k in ("clusters", "objects"):
                for col in r[k]:
                    self.assertTrue(np.array_equal(np.asarray(r[k][col]),
                                                   np.asarray(self.via_run_scenario[k][col])), (k, col))
            else:
                self.assertEqual(r[k], self.via_run_scenario[k], k)

    def step_rows(self):
        """clusters.csv's rows rebuilt from the steps, in its order (per step, mode by mode)."""
        rows = []
        for s in self.steps:
            for mode in s.modes:
                for c in s.clusters[mode]:
                    rows.append((s.step, s.time, mode, c, s.ego_pose))
        return rows

    def test_every_steps_clusters_equal_clusters_csv(self):
        rows = self.step_rows()
        self.assertEqual(len(rows), len(self.cli_clusters))
        self.assertGreater(len(rows), 0)
        for (step, time, mode, c, _), cli in zip(rows, self.cli_clusters):
            self.assertEqual(step, int(cli["step"]))
            self.assertEqual(f"{time:.3f}", cli["time"])
            self.assertEqual(mode, cli["mode"])
            for k in ("x", "y", "vx", "vy"):
                self.assertAlmostEqual(float(c[k]), float(cli[k]), delta=0.0005 + 1e-9)
            self.assertEqual(int(c["particles"]), int(cli["particles"]))
            self.assertEqual(dualgrid.ROLE_NAMES[c["role"]], cli["role"])
            name = self.steps[0].names.get(int(c["object"])) if c["object"] >= 0 else ""
            if c["object"] >= 0:
                name = self.results["object_names"][str(int(c["object"]))]
            self.assertEqual(name, cli["object"])

    def test_same_digest_as_the_cli(self):
        # clusters.csv rebuilt byte for byte from the steps (tools/src/run_outputs.cpp's format:
        # %.3f, weight as %.10g, the ego-frame position from the step's ego pose, %.2f) has the
        # digest summary.json records for the CLI's file.
        with open(os.path.join(self.cli_dir, "clusters.csv"), "rb") as f:
            header = f.readline().decode()
        with open(os.path.join(self.cli_dir, "summary.json")) as f:
            recorded = json.load(f)["digests"]["clusters.csv"]
        lines = [header]
        names = self.results["object_names"]
        for step, time, mode, c, (ex, ey, yaw) in self.step_rows():
            co, si = np.cos(yaw), np.sin(yaw)
            dx, dy = c["x"] - ex, c["y"] - ey
            lx, ly = co * dx + si * dy, -si * dx + co * dy
            obj = names[str(int(c["object"]))] if c["object"] >= 0 else ""
            lines.append(f"{step},{time:.3f},{mode},{c['x']:.3f},{c['y']:.3f},{c['vx']:.3f},"
                         f"{c['vy']:.3f},{c['weight']:.10g},{c['particles']},"
                         f"{dualgrid.ROLE_NAMES[c['role']]},{obj},{lx:.2f},{ly:.2f}\n")
        self.assertEqual(fnv1a64("".join(lines).encode()), recorded)

    def test_step_scores_add_up_to_the_metrics(self):
        for mode in ("position", "velocity", "dual"):
            m = self.results["metrics"][mode]
            cells = sum(s.scores[mode]["cells"] for s in self.steps)
            self.assertEqual(cells.tolist(), m["cells"]["confusion_truth_by_predicted"], mode)
            self.assertEqual(sum(s.scores[mode]["matched"] for s in self.steps), m["matches"])
            dup = sum(s.scores[mode]["duplicate"] for s in self.steps) / len(self.steps)
            self.assertAlmostEqual(dup, m["duplicate_clusters_per_scan"], places=12)
            false = sum(s.scores[mode]["false"] for s in self.steps) / len(self.steps)
            self.assertAlmostEqual(false, m["false_clusters_per_scan"], places=12)

    def test_grid_arrays(self):
        s = max(self.steps, key=lambda s: len(s.clusters["dual"]))  # a step with clusters
        for mode, g in s.grids.items():
            ny, nx = g.classes.shape
            self.assertEqual(g.masses.shape, (ny, nx, 3))
            self.assertEqual(g.masses.dtype, np.float32)
            self.assertEqual(g.velocity.shape, (ny, nx, 2))
            self.assertEqual(g.observed.dtype, bool)
            self.assertTrue(np.all(g.masses >= 0))
            self.assertTrue(np.all(g.masses.sum(axis=2) <= 1 + 1e-5))
            self.assertEqual(g.frame, "grid")
            # Cell centres: one resolution apart, inside the extent.
            self.assertEqual((len(g.x), len(g.y)), (nx, ny))
            self.assertTrue(np.allclose(np.diff(g.x), g.resolution))
            x0, x1, y0, y1 = g.extent
            self.assertAlmostEqual(g.x[0], x0 + g.resolution / 2)
            self.assertAlmostEqual(g.y[-1], y1 - g.resolution / 2)
            # The classes are those of the masses at the scenario's threshold (0.6).
            dyn = g.masses[..., 2] > 0.6
            self.assertTrue(np.array_equal(g.classes == 2, dyn))
            # The ego lies in the grid; moving cells carry velocity (the dual mode tracks here).
            ex, ey, _ = s.ego_pose
            self.assertTrue(x0 <= ex <= x1 and y0 <= ey <= y1)
            if mode == "dual":
                self.assertTrue(dyn.any())
                self.assertGreater(np.abs(g.velocity[dyn]).max(), 1.0)
        # Read-only views that outlive later steps: the first step's arrays are unchanged.
        first = self.steps[0].grids["dual"].masses
        with self.assertRaises(ValueError):
            first[0, 0, 0] = 1.0
        self.assertFalse(np.array_equal(first, self.steps[-1].grids["dual"].masses))

    def test_detections_and_truth(self):
        total = sum(len(s.detections) for s in self.steps)
        self.assertAlmostEqual(total / len(self.steps), self.results["detections_per_step"])
        s = self.steps[-1]
        d = pd.DataFrame(s.detections)
        self.assertGreater(len(d), 0)
        # Eq. (1): v_r is the compensated radial speed along the line of sight.
        los = np.stack([d.x - d.sensor_x, d.y - d.sensor_y], axis=1)
        los /= np.linalg.norm(los, axis=1)[:, None]
        v = np.stack([d.v_rx, d.v_ry], axis=1)
        self.assertTrue(np.allclose(v, los * d.radial_speed_compensated.to_numpy()[:, None]))
        t = s.truth
        self.assertGreater(len(t), 0)
        self.assertEqual(set(s.names), set(int(i) for i in t["id"]))
        scored = set(self.results["object_names"].values())
        self.assertTrue({s.names[int(i)] for i in t["id"][t["in_grid"]]} <= scored)
        # Direct returns name a truth object or a static obstacle.
        self.assertTrue(((d.source_id >= 0) | d.is_clutter).any())

    def test_times_and_ego(self):
        times = np.array([s.time for s in self.steps])
        self.assertTrue(np.allclose(np.diff(times), self.sim.step_length))
        poses = np.array([s.ego_pose for s in self.steps])
        speed = np.linalg.norm(np.diff(poses[:, :2], axis=0), axis=1) / self.sim.step_length
        v = np.linalg.norm(np.array([s.ego_velocity for s in self.steps]), axis=1)
        self.assertTrue(np.allclose(speed, v[1:], atol=0.5))


if __name__ == "__main__":
    unittest.main()
