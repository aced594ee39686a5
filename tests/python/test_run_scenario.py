"""dualgrid.run_scenario (python/src/cosim_bindings.cpp) against the command line: the same
scenario and seed give the CLI's metrics.json, objects and clusters.csv; bad input is ValueError.

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
DURATION = 6.0
SEED = 3


class RunScenarioTest(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        out = os.path.join(cls.tmp.name, "cli")
        subprocess.run([os.environ["DUALGRID_EXE"], "run", SCENARIO, "--out", out, "--seed",
                        str(SEED), "--duration", str(DURATION), "--no-figures", "-q",
                        "--set", "filter.preset=paper"], check=True)
        with open(os.path.join(out, "metrics.json")) as f:
            cls.cli = json.load(f)
        with open(os.path.join(out, "clusters.csv")) as f:
            cls.cli_clusters = list(csv.DictReader(f))
        # Two threads here, the CLI's default on this machine may differ: results must not care.
        cls.py = dualgrid.run_scenario(SCENARIO, seed=SEED, duration=DURATION,
                                       overrides=["filter.preset=paper"], threads=2)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_metrics_equal_the_cli(self):
        r = self.py
        self.assertTrue(r["complete"])
        self.assertEqual(r["steps"], self.cli["steps"])
        self.assertEqual(r["seed"], SEED)
        self.assertEqual(set(r["metrics"]), {"position", "velocity", "dual"})
        for mode, m in self.cli["modes"].items():
            self.assertEqual(r["metrics"][mode], m, mode)
        self.assertEqual(r["object_names"], self.cli["object_names"])
        # Not vacuous: objects were scored and tracked.
        self.assertGreater(r["metrics"]["dual"]["objects_scored"], 0)
        self.assertGreater(r["metrics"]["dual"]["matches"], 0)

    def test_clusters_equal_clusters_csv(self):
        c = self.py["clusters"]
        self.assertEqual(len(c["x"]), len(self.cli_clusters))
        self.assertGreater(len(c["x"]), 0)
        for i, row in enumerate(self.cli_clusters):
            self.assertEqual(c["mode"][i], row["mode"])
            self.assertEqual(int(c["step"][i]), int(row["step"]))
            self.assertEqual(c["role"][i], row["role"])
            self.assertEqual(c["object"][i], row["object"])
            self.assertEqual(int(c["particles"][i]), int(row["particles"]))
            # clusters.csv holds 3 decimals.
            for k in ("x", "y", "vx", "vy"):
                self.assertAlmostEqual(float(c[k][i]), float(row[k]), delta=0.0005 + 1e-9)

    def test_results_go_into_pandas(self):
        clusters = pd.DataFrame(self.py["clusters"])
        objects = pd.DataFrame(self.py["objects"])
        self.assertEqual(len(clusters), len(self.cli_clusters))
        self.assertTrue(np.issubdtype(clusters["x"].dtype, np.floating))
        # One row per (mode, object ever in the grid), as objects.csv.
        per_mode = objects.groupby("mode").size()
        for mode, m in self.cli["modes"].items():
            self.assertEqual(per_mode[mode], len(m["objects"]))
        self.assertTrue(set(objects["name"]) <= set(self.cli["object_names"].values()))

    def test_bad_input_is_value_error(self):
        with self.assertRaisesRegex(ValueError, "unknown mode 'fast'"):
            dualgrid.run_scenario(SCENARIO, modes=["fast"])
        with self.assertRaisesRegex(ValueError, "filter.sigma_v"):
            dualgrid.run_scenario(SCENARIO, duration=1.0, overrides=["filter.sigma_v=-1"])
        with self.assertRaisesRegex(ValueError, "duration"):
            dualgrid.run_scenario(SCENARIO, duration=-1.0)
        with self.assertRaisesRegex(ValueError, "not found"):
            dualgrid.run_scenario("no/such/scenario.yaml")


class RunFolderTest(unittest.TestCase):
    """run_scenario(..., out=DIR) writes the command line's run folder: every file the same bytes,
    summary.json the same but for its wall-clock time."""

    def test_run_folder_equals_the_cli(self):
        networks = os.path.join(os.path.dirname(os.environ["DUALGRID_EXE"]), os.pardir, "share",
                                "dualgrid", "networks")
        with tempfile.TemporaryDirectory() as tmp:
            cli, py = os.path.join(tmp, "cli"), os.path.join(tmp, "py")
            subprocess.run([os.environ["DUALGRID_EXE"], "run", SCENARIO, "--out", cli, "--seed",
                            str(SEED), "--duration", "4", "--network-dir", networks, "-q",
                            "--set", "filter.num_particles=20000"], check=True)
            r = dualgrid.run_scenario(SCENARIO, seed=SEED, duration=4.0, out=py,
                                      network_dir=networks, threads=1,
                                      overrides=["filter.num_particles=20000"])
            self.assertTrue(r["complete"])
            files = {}
            for root in (cli, py):
                files[root] = sorted(os.path.relpath(os.path.join(d, f), root)
                                     for d, _, names in os.walk(root) for f in names)
            self.assertEqual(files[cli], files[py])
            # Not vacuous: the folder has its results, figures and replay.
            for f in ("metrics.json", "objects.csv", "clusters.csv", "table.md", "config.json",
                      "scenario.yaml", "figures/tracked_share.png", "replay/index.json"):
                self.assertIn(f, files[cli])
            for f in files[cli]:
                with open(os.path.join(cli, f), "rb") as a, open(os.path.join(py, f), "rb") as b:
                    ca, cb = a.read(), b.read()
                if f == "summary.json":
                    ja, jb = json.loads(ca), json.loads(cb)
                    self.assertGreater(len(ja["digests"]), 10)
                    ja.pop("wall_s")
                    jb.pop("wall_s")
                    self.assertEqual(ja, jb)
                elif f != "sumo.log":  # SUMO's own log, dated
                    self.assertEqual(ca, cb, f)
            # A second run into the folder is refused before SUMO starts, unless force=True.
            with self.assertRaisesRegex(ValueError, "run_scenario: out: .* add force=True"):
                dualgrid.run_scenario(SCENARIO, seed=SEED, duration=4.0, out=py,
                                      network_dir=networks)
            with self.assertRaisesRegex(ValueError, "work_dir"):
                dualgrid.run_scenario(SCENARIO, duration=0.5, work_dir=os.path.dirname(SCENARIO),
                                      network_dir=networks)


if __name__ == "__main__":
    unittest.main()
