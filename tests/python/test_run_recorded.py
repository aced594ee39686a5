"""dualgrid.run_recorded (python/src/recorded_bindings.cpp) against `dualgrid filter`: the same
RadarScenes sequence (written by h5py from the public schema: tests/recorded/make_radarscenes.py)
gives the CLI's metrics.json (point scores included) and clusters.csv; bad input is ValueError.

Needs DUALGRID_EXE and DUALGRID_SOURCE_DIR; run against the installed package (tests/python)."""

import csv
import json
import os
import re
import subprocess
import sys
import tempfile
import unittest

import numpy as np

import dualgrid

SOURCE = os.environ.get("DUALGRID_SOURCE_DIR", ".")
MAKE = os.path.join(SOURCE, "tests", "recorded", "make_radarscenes.py")
# h5py is Debian's python3-h5py: for /usr/bin/python3, whichever python runs this module.
H5PY_PYTHON = os.environ.get("DUALGRID_H5PY_PYTHON", sys.executable)


class RunRecordedTest(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        root = os.path.join(cls.tmp.name, "rs")
        subprocess.run([H5PY_PYTHON, MAKE, "--out", root, "--duration", "3"], check=True,
                       capture_output=True)
        cls.seq = os.path.join(root, "data", "sequence_1")
        out = os.path.join(cls.tmp.name, "cli")
        subprocess.run([os.environ["DUALGRID_EXE"], "filter", cls.seq, "--out", out, "--seed", "5",
                        "--no-figures", "-q"], check=True)
        with open(os.path.join(out, "metrics.json")) as f:
            cls.cli = json.load(f)
        with open(os.path.join(out, "clusters.csv")) as f:
            cls.cli_clusters = list(csv.DictReader(f))
        cls.py = dualgrid.run_recorded(cls.seq, seed=5, threads=2)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_metrics_equal_the_cli(self):
        r = self.py
        self.assertTrue(r["complete"])
        self.assertEqual(r["steps"], self.cli["steps"])
        for mode, m in self.cli["modes"].items():
            self.assertEqual(r["metrics"][mode], m, mode)
        # Not vacuous: labelled points were scored, the car tracked.
        self.assertGreater(r["metrics"]["dual"]["points"]["true_positives"], 0)
        self.assertGreater(r["metrics"]["dual"]["matches"], 0)
        self.assertEqual(r["input"]["kind"], "radarscenes")
        self.assertTrue(r["input"]["labels"])

    def test_clusters_equal_clusters_csv(self):
        c = self.py["clusters"]
        self.assertEqual(len(c["x"]), len(self.cli_clusters))
        self.assertGreater(len(c["x"]), 0)
        for i, row in enumerate(self.cli_clusters):
            self.assertEqual(c["mode"][i], row["mode"])
            self.assertEqual(f"{c['time'][i]:.3f}", row["time"])
            self.assertEqual(f"{c['x'][i]:.3f}", row["x"])
            self.assertEqual(f"{c['vy'][i]:.3f}", row["vy"])

    def test_stepped_equals_run_recorded(self):
        sim = dualgrid.RecordedSimulation(self.seq, seed=5, modes=["velocity", "dual"])
        steps = list(sim)
        r = sim.results()
        self.assertEqual(len(steps), self.cli["steps"])
        for mode in ("velocity", "dual"):
            self.assertEqual(r["metrics"][mode], self.cli["modes"][mode], mode)
            clusters = [c for s in steps for c in s.clusters[mode]]
            cli = [row for row in self.cli_clusters if row["mode"] == mode]
            self.assertEqual([f"{c['x']:.3f}" for c in clusters], [row["x"] for row in cli])
        self.assertEqual(r["input"], self.py["input"])
        # Labelled points come with the detections; the scans' times increase.
        labels = np.concatenate([s.detections["label"] for s in steps])
        self.assertGreater(np.count_nonzero(labels >= 0), 0)
        self.assertTrue(np.all(np.diff([s.time for s in steps]) > 0))

    def test_read_recorded_without_filtering(self):
        r = dualgrid.read_recorded(self.seq)
        pts, scans = r["points"], r["scans"]
        self.assertEqual(r["kind"], "radarscenes")
        self.assertEqual(len(pts["x"]), self.py["input"]["detections"])
        self.assertEqual(len(scans["time"]), self.py["input"]["scans"])
        self.assertEqual(int(scans["points"].sum()), len(pts["x"]))
        self.assertEqual(len(r["track_names"]), self.py["input"]["tracks"])
        # Every point carries its scan's time and sensor; scans in time order.
        self.assertTrue(np.array_equal(pts["time"], scans["time"][pts["scan"]]))
        self.assertTrue(np.array_equal(pts["sensor"], scans["sensor"][pts["scan"]]))
        self.assertTrue(np.all(np.diff(scans["timestamp_us"]) >= 0))
        self.assertTrue(np.all(np.isfinite(pts["x"])) and np.all(pts["range"] > 0))
        # Labelled: moving points (labels 0..10) and their tracks; the sensors as SensorParams.
        moving = (pts["label"] >= 0) & (pts["label"] < 11)
        self.assertGreater(np.count_nonzero(moving), 0)
        self.assertTrue(np.all(pts["track"][moving] >= 0))
        self.assertTrue(all(isinstance(s, dualgrid.SensorParams) for s in r["sensors"]))
        import pandas as pd
        self.assertEqual(len(pd.DataFrame(pts)), len(pts["x"]))
        with self.assertRaisesRegex(ValueError, "scenes.json"):
            dualgrid.read_recorded(self.tmp.name)

    def test_bad_input_is_value_error(self):
        with self.assertRaisesRegex(ValueError, "scenes.json"):
            dualgrid.run_recorded(self.tmp.name)
        with self.assertRaisesRegex(ValueError, "unknown mode"):
            dualgrid.run_recorded(self.seq, modes=["fast"])


class ExportTest(unittest.TestCase):
    """export_radarscenes writes what `dualgrid export` writes: both read back the same."""

    def test_export_equals_the_cli(self):
        with tempfile.TemporaryDirectory() as tmp:
            run = os.path.join(tmp, "run")
            subprocess.run([os.environ["DUALGRID_EXE"], "run",
                            os.path.join(SOURCE, "scenarios", "simple_road.yaml"), "--out", run,
                            "--duration", "2", "--modes", "dual", "--detections", "exact",
                            "--no-figures", "--no-record", "-q"], check=True)
            cli = os.path.join(tmp, "cli")
            subprocess.run([os.environ["DUALGRID_EXE"], "export", run, "--out", cli, "-q"],
                           check=True)
            seq = dualgrid.export_radarscenes(run, os.path.join(tmp, "py"))
            self.assertEqual(seq, os.path.join(tmp, "py", "data", "sequence_1"))
            a = dualgrid.read_recorded(seq)
            b = dualgrid.read_recorded(os.path.join(cli, "data", "sequence_1"))
            self.assertGreater(len(a["points"]["x"]), 100)
            for part in ("points", "scans"):
                for k in a[part]:
                    self.assertTrue(np.array_equal(a[part][k], b[part][k]), (part, k))
            self.assertEqual(a["track_names"], b["track_names"])
            # The output guard (docs/reliability.md, "Output folders"), as on the command line.
            with self.assertRaisesRegex(ValueError, "add force=True"):
                dualgrid.export_radarscenes(run, os.path.join(tmp, "py"))
            self.assertEqual(dualgrid.export_radarscenes(run, os.path.join(tmp, "py"), force=True),
                             seq)
            for out in (run, os.path.join(run, "inside"), tmp):
                with self.assertRaisesRegex(ValueError, re.escape("out '" + out)):
                    dualgrid.export_radarscenes(run, out, force=True)
            for name in ("../x", "/tmp/x", "..", "", "a\nb"):
                with self.assertRaisesRegex(ValueError, "sequence"):
                    dualgrid.export_radarscenes(run, os.path.join(tmp, "n"), sequence=name)
            self.assertFalse(os.path.exists(os.path.join(tmp, "x")))
            os.rename(os.path.join(run, "summary.json"), os.path.join(tmp, "summary.json"))
            with self.assertRaisesRegex(ValueError, "not a finished run"):
                dualgrid.export_radarscenes(run, os.path.join(tmp, "inc"))
            dualgrid.export_radarscenes(run, os.path.join(tmp, "inc"), allow_incomplete=True)
            self.assertTrue(os.path.isfile(os.path.join(tmp, "inc", "INCOMPLETE.txt")))


if __name__ == "__main__":
    unittest.main()
