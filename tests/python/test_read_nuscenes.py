"""dualgrid.read_nuscenes / read_radarscenes (python/src/nuscenes_bindings.cpp): the recorded-data
readers as numpy columns. The nuScenes scene is written by tests/recorded/make_nuscenes.py (numpy +
json from the public schema), whose objects move at known constant velocities, so the devkit's
annotation velocities are exact there; the readers' counts match `dualgrid filter`'s summary.

Needs DUALGRID_EXE and DUALGRID_SOURCE_DIR; run against the installed package (tests/python)."""

import json
import math
import os
import subprocess
import sys
import tempfile
import unittest

import numpy as np

import dualgrid

SOURCE = os.environ.get("DUALGRID_SOURCE_DIR", ".")
MAKE_NS = os.path.join(SOURCE, "tests", "recorded", "make_nuscenes.py")
MAKE_RS = os.path.join(SOURCE, "tests", "recorded", "make_radarscenes.py")
H5PY_PYTHON = os.environ.get("DUALGRID_H5PY_PYTHON", sys.executable)
EXE = os.environ.get("DUALGRID_EXE", "dualgrid")


class ReadNuScenesTest(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.root = os.path.join(cls.tmp.name, "ns")
        out = subprocess.run([sys.executable, MAKE_NS, "--out", cls.root, "--duration", "4"],
                             check=True, capture_output=True, text=True).stdout
        cls.truth = json.loads(out)
        cls.r = dualgrid.read_nuscenes(cls.root, "scene-test")

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_points_and_scans(self):
        p, s = self.r["points"], self.r["scans"]
        self.assertEqual(self.r["channels"][0], "RADAR_FRONT")
        self.assertEqual(len(self.r["channels"]), 5)
        self.assertTrue(np.all(np.diff(s["timestamp"]) >= 0), "scans in time order")
        self.assertEqual(int(s["end"][-1]), len(p["x"]))
        self.assertTrue(np.all(np.isfinite(p["radial_speed"])))
        # The same count as the command line's reader.
        run = os.path.join(self.tmp.name, "run")
        subprocess.run([EXE, "filter", self.root, "--scene", "scene-test", "--modes", "dual",
                        "--no-figures", "-q", "--out", run], check=True)
        with open(os.path.join(run, "summary.json")) as f:
            inp = json.load(f)["input"]
        self.assertEqual(inp["detections"], len(p["x"]))
        self.assertEqual(inp["filtered_points"], self.r["filtered_points"])

    def test_annotations_velocity_exact_for_constant_motion(self):
        a = self.r["annotations"]
        self.assertEqual(set(a["instance"]), {"inst-lead", "inst-cross", "inst-parked"})
        self.assertEqual(self.r["skipped_instances"], 1)
        for i, inst in enumerate(a["instance"]):
            tv = self.truth[inst]["velocity"]
            self.assertAlmostEqual(a["vx"][i], tv[0], places=6)
            self.assertAlmostEqual(a["vy"][i], tv[1], places=6)
            self.assertEqual(bool(a["moving"][i]), math.hypot(*tv) > 1.0)

    def test_point_labels(self):
        p = self.r["points"]
        track = np.array(p["track"])
        self.assertGreater(np.sum(track == "inst-lead"), 20)
        self.assertTrue(np.all(p["label"][track == ""] == 11))
        self.assertTrue(np.all(p["label"][track == "inst-cross"] == 0))

    def test_filters_and_errors(self):
        every = dualgrid.read_nuscenes(self.root, "scene-test", invalid_states=None)
        self.assertEqual(len(every["points"]["x"]),
                         len(self.r["points"]["x"]) + self.r["filtered_points"])
        with self.assertRaisesRegex(ValueError, "no scene named"):
            dualgrid.read_nuscenes(self.root, "scene-none")


class ReadRadarScenesTest(unittest.TestCase):

    def test_columns(self):
        with tempfile.TemporaryDirectory() as tmp:
            root = os.path.join(tmp, "rs")
            subprocess.run([H5PY_PYTHON, MAKE_RS, "--out", root, "--duration", "1"], check=True,
                           capture_output=True)
            r = dualgrid.read_radarscenes(os.path.join(root, "data", "sequence_1"))
        p = r["points"]
        self.assertGreater(len(p["x"]), 50)
        self.assertEqual(set(np.unique(p["label"])), {0, 11})
        self.assertEqual(set(p["track"]), {"car-1", ""})
        self.assertEqual(len(r["sensors"]), 4)


if __name__ == "__main__":
    unittest.main()
