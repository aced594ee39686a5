"""The radar model from Python: scene input forms and errors, the detections table, coverage and
detections_to_measurements (python/src/radar_bindings.cpp, python/dualgrid/__init__.py)."""

import math
import unittest

import numpy as np

import dualgrid

COLUMNS = [
    "sensor", "range", "azimuth", "range_rate", "snr_db", "x", "y", "x_ego", "y_ego",
    "radial_speed_compensated", "v_rx", "v_ry", "sensor_x", "sensor_y", "source_id", "is_clutter",
    "path", "bounces", "reflector_id", "ghost_of"
]

EGO = dualgrid.EgoMotion(pose=(5.0, 1.0, 0.1), velocity=(10.0, 1.0), length=4.5, width=1.8)
CAR = dict(id=7, x=30.0, y=3.0, yaw=0.3, length=4.5, width=1.8, vx=-8.0, vy=2.0)
RAIL = dict(id=9, points=[[-50.0, -6.0], [150.0, -6.0]], rcs_dbsm_per_metre=-5.0)


def box_distance(x, y, target):
    """Distance [m] of (x, y) from the boundary of a target's box."""
    c, s = math.cos(target["yaw"]), math.sin(target["yaw"])
    dx, dy = x - target["x"], y - target["y"]
    a = abs(c * dx + s * dy) - 0.5 * target["length"]
    b = abs(-s * dx + c * dy) - 0.5 * target["width"]
    outside = math.hypot(max(a, 0.0), max(b, 0.0))
    return outside if outside > 0 else -max(a, b)


class ScanTest(unittest.TestCase):

    def setUp(self):
        self.radar = dualgrid.RadarModel(dualgrid.default_rig(4.5, 1.8), seed=11)

    def test_table_columns(self):
        d = self.radar.scan(EGO, {"targets": [CAR], "polylines": [RAIL]}, step=3, time=0.15)
        self.assertEqual(list(d), COLUMNS)
        n = len(d["x"])
        self.assertGreater(n, 0)
        for k, a in d.items():
            self.assertEqual(a.shape, (n,), k)
        self.assertEqual(d["sensor"].dtype, np.int32)
        self.assertEqual(d["source_id"].dtype, np.int32)
        self.assertEqual(d["is_clutter"].dtype, bool)
        np.testing.assert_array_equal(d["is_clutter"], d["source_id"] == -1)
        self.assertEqual(set(d["source_id"]) - {-1}, {7, 9})
        # eq. (1): v_r = radial_speed_compensated times the world line of sight from the sensor.
        los = np.stack([d["x"] - d["sensor_x"], d["y"] - d["sensor_y"]], axis=1)
        los /= np.linalg.norm(los, axis=1)[:, None]
        np.testing.assert_allclose(d["v_rx"], d["radial_speed_compensated"] * los[:, 0],
                                   atol=1e-9)
        np.testing.assert_allclose(d["v_ry"], d["radial_speed_compensated"] * los[:, 1],
                                   atol=1e-9)
        # range and world position agree through the sensor position.
        np.testing.assert_allclose(
            np.hypot(d["x"] - d["sensor_x"], d["y"] - d["sensor_y"]), d["range"], atol=1e-9)
        import pandas as pd
        df = pd.DataFrame(d)
        self.assertEqual(list(df.columns), COLUMNS)
        self.assertEqual(len(df), n)

    def test_noise_free_detections_lie_on_the_target(self):
        radar = dualgrid.RadarModel(dualgrid.default_rig(4.5, 1.8),
                                    dualgrid.ModelOptions(noise=False, false_alarms=False), seed=1)
        d = radar.scan(EGO, dualgrid.Scene(targets=[CAR]), step=0, time=0.0)
        self.assertGreater(len(d["x"]), 3)
        self.assertFalse(d["is_clutter"].any())
        for x, y in zip(d["x"], d["y"]):
            # Without noise a detection is the SNR-weighted centroid of its resolution cell's
            # scatterers on the box faces: on the boundary, or a few mm inside where a cell
            # spans a corner.
            self.assertLess(abs(box_distance(x, y, CAR)), 0.05)
        # Over ground the compensated radial speed is the target's velocity on the line of sight
        # (up to the centroid's averaging over the cell's lines of sight: mm/s).
        los = np.stack([d["x"] - d["sensor_x"], d["y"] - d["sensor_y"]], axis=1)
        los /= np.linalg.norm(los, axis=1)[:, None]
        np.testing.assert_allclose(d["radial_speed_compensated"], los @ [CAR["vx"], CAR["vy"]],
                                   atol=0.02)

    def test_deterministic_in_seed_and_step(self):
        scene = {"targets": [CAR], "polylines": [RAIL]}
        a = self.radar.scan(EGO, scene, step=4, time=0.2)
        b = dualgrid.RadarModel(dualgrid.default_rig(4.5, 1.8), seed=11).scan(EGO, scene, step=4,
                                                                               time=0.2)
        c = self.radar.scan(EGO, scene, step=5, time=0.2)
        for k in a:
            np.testing.assert_array_equal(a[k], b[k], err_msg=k)
        # Another step draws other noise.
        self.assertTrue(len(a["range"]) != len(c["range"]) or
                        not np.array_equal(a["range"], c["range"]))

    def test_scene_forms_agree(self):
        table = np.array([[CAR[k] if k in CAR else {"yaw_rate": 0.0, "rcs_dbsm": 10.0}[k]
                           for k in dualgrid.TARGET_COLUMNS]])
        cols = {k: table[:, i] for i, k in enumerate(dualgrid.TARGET_COLUMNS)}
        ref = self.radar.scan(EGO, {"targets": [CAR]}, step=1, time=0.05)
        for targets in (table, cols, dualgrid.Scene(targets=table)):
            scene = targets if isinstance(targets, dualgrid.Scene) else {"targets": targets}
            got = self.radar.scan(EGO, scene, step=1, time=0.05)
            for k in ref:
                np.testing.assert_array_equal(got[k], ref[k], err_msg=k)
        s = dualgrid.Scene(targets=[CAR], polylines=[RAIL])
        self.assertEqual(s.targets["id"].tolist(), [7])
        self.assertEqual(s.targets["rcs_dbsm"].tolist(), [10.0])
        np.testing.assert_array_equal(s.polylines[0]["points"], RAIL["points"])

    def test_scene_errors(self):
        with self.assertRaisesRegex(ValueError, r"targets: expected a float array of shape "
                                    r"\(N, 10\) with columns \[id, x, y, yaw, length, width, vx, "
                                    r"vy, yaw_rate, rcs_dbsm\], got shape \(1, 9\)"):
            dualgrid.Scene(targets=np.zeros((1, 9)))
        with self.assertRaisesRegex(ValueError, r"targets\[0\]: missing key 'width'"):
            dualgrid.Scene(targets=[dict(id=1, x=0, y=0, length=4)])
        with self.assertRaisesRegex(ValueError, r"targets\[0\]: unknown key 'rcs'"):
            dualgrid.Scene(targets=[dict(CAR, rcs=5.0)])
        with self.assertRaisesRegex(ValueError, "targets: row 1: id 7 is used twice"):
            dualgrid.Scene(targets=[CAR, CAR])
        with self.assertRaisesRegex(ValueError, r"polylines\[0\]: id 7 is used twice"):
            dualgrid.Scene(targets=[CAR], polylines=[dict(RAIL, id=7)])
        with self.assertRaisesRegex(ValueError, "targets: row 0: length and width must be > 0"):
            dualgrid.Scene(targets=[dict(CAR, width=0.0)])
        with self.assertRaisesRegex(ValueError, "targets: row 0: id must be an integer"):
            dualgrid.Scene(targets=[dict(CAR, id=1.5)])
        with self.assertRaisesRegex(ValueError, r"polylines\[0\]\['points'\]: expected an array "
                                    r"\(P, 2\) \[m\] with P >= 2, got 1 point"):
            dualgrid.Scene(polylines=[dict(id=1, points=[[0.0, 0.0]])])
        with self.assertRaisesRegex(ValueError, r"polylines\[0\]\['points'\]: expected a float "
                                    r"array of shape \(N, 2\)"):
            dualgrid.Scene(polylines=[dict(id=1, points=[[0.0, 0.0, 1.0]] * 3)])
        with self.assertRaisesRegex(ValueError, "scene: unknown key 'target'"):
            self.radar.scan(EGO, {"target": [CAR]}, step=0, time=0.0)
        with self.assertRaisesRegex(ValueError, "scene: expected a Scene or a dict"):
            self.radar.scan(EGO, [CAR], step=0, time=0.0)
        with self.assertRaisesRegex(ValueError, "ego: .*unknown field 'speed'"):
            self.radar.scan({"pose": (0, 0, 0), "speed": 3.0}, {}, step=0, time=0.0)
        with self.assertRaisesRegex(ValueError, "step_length: must be finite and > 0"):
            self.radar.scan(EGO, {}, step=0, time=0.0, step_length=0.0)
        with self.assertRaises(IndexError):
            self.radar.scan_sensor(5, EGO, {}, step=0)

    def test_ego_as_dict_and_scan_sensor(self):
        ego = {"pose": EGO.pose, "velocity": EGO.velocity, "length": 4.5, "width": 1.8}
        scene = {"targets": [CAR]}
        a = self.radar.scan(EGO, scene, step=2, time=0.1)
        b = self.radar.scan(ego, scene, step=2, time=0.1)
        np.testing.assert_array_equal(a["x"], b["x"])
        # scan() is the concatenation of the due sensors' scan_sensor() results.
        parts = [self.radar.scan_sensor(s, EGO, scene, step=2)
                 for s in self.radar.sensors_due(0.1, 0.05)]
        np.testing.assert_array_equal(a["range"], np.concatenate([p["range"] for p in parts]))

    def test_sensors_due_and_coverage(self):
        rig = dualgrid.default_rig(4.5, 1.8)
        rig[4].update_period = 0.1  # the front radar every other 50 ms step
        radar = dualgrid.RadarModel(rig, seed=1)
        self.assertEqual(radar.sensors_due(0.0, 0.05), [0, 1, 2, 3, 4])
        self.assertEqual(radar.sensors_due(0.05, 0.05), [0, 1, 2, 3])
        cov = radar.coverage(EGO.pose, [1, 4])
        self.assertEqual(cov.shape, (2, 6))
        for row, s in zip(cov, (1, 4)):
            x, y, yaw = radar.sensor_pose(s, EGO.pose)
            np.testing.assert_allclose(row, [x, y, yaw, 0.5 * rig[s].fov, rig[s].min_range,
                                             rig[s].max_range])
        self.assertEqual(radar.coverage(EGO.pose).shape, (5, 6))
        # front radar: at the front bumper centre, 2.25 m ahead of the ego centre along yaw 0.1
        fx, fy, fyaw = radar.sensor_pose(4, EGO.pose)
        self.assertAlmostEqual(fx, 5.0 + 2.25 * math.cos(0.1))
        self.assertAlmostEqual(fy, 1.0 + 2.25 * math.sin(0.1))
        self.assertAlmostEqual(fyaw, 0.1)


class MeasurementsTest(unittest.TestCase):

    def test_detections_to_measurements(self):
        radar = dualgrid.RadarModel(dualgrid.default_rig(4.5, 1.8), seed=2)
        d = radar.scan(EGO, {"targets": [CAR], "polylines": [RAIL]}, step=0, time=0.0)
        z = dualgrid.detections_to_measurements(d)
        self.assertEqual(z.shape, (len(d["x"]), 6))
        np.testing.assert_array_equal(z[:, 2], d["v_rx"])
        np.testing.assert_array_equal(z[:, 5], d["sensor_y"])
        clean = dualgrid.detections_to_measurements(d, include_clutter=False)
        self.assertEqual(len(clean), int((~d["is_clutter"]).sum()))
        # Clutter drawn down to the sensors' minimum range lands inside the ego's body; the
        # ego box removes exactly the detections inside it.
        inside = np.array([box_distance(x, y, dict(x=EGO.pose[0], y=EGO.pose[1], yaw=EGO.pose[2],
                                                    length=4.5, width=1.8)) <= 0
                           for x, y in zip(d["x"], d["y"])])
        kept = dualgrid.detections_to_measurements(d, ego_box=EGO)
        self.assertEqual(len(kept), int((~inside).sum()))
        kept2 = dualgrid.detections_to_measurements(d, ego_box=(*EGO.pose, 4.5, 1.8))
        np.testing.assert_array_equal(kept, kept2)
        with self.assertRaisesRegex(ValueError, r"detections: missing column\(s\) \['v_rx'\]"):
            dualgrid.detections_to_measurements({k: v for k, v in d.items() if k != "v_rx"})
        with self.assertRaisesRegex(ValueError, "ego_box: expected an EgoMotion or"):
            dualgrid.detections_to_measurements(d, ego_box=(0, 0, 0))
        empty = dualgrid.detections_to_measurements({k: d[k][:0] for k in d})
        self.assertEqual(empty.shape, (0, 6))

    def test_scan_dict_feeds_the_grid_directly(self):
        radar = dualgrid.RadarModel(dualgrid.default_rig(4.5, 1.8), seed=2)
        d = radar.scan(EGO, {"targets": [CAR]}, step=0, time=0.0)
        cov = radar.coverage(EGO.pose)
        p = dualgrid.FilterParams(num_particles=2000, num_birth=200)
        g1, g2 = dualgrid.DynamicGrid(p, 1), dualgrid.DynamicGrid(p, 1)
        g1.update(EGO.pose, EGO.velocity, d, cov, dt=0.05)
        g2.update(EGO.pose, EGO.velocity, dualgrid.detections_to_measurements(d), cov, dt=0.05)
        np.testing.assert_array_equal(g1.masses()["dynamic"], g2.masses()["dynamic"])


if __name__ == "__main__":
    unittest.main()
