"""dualgrid.DynamicGrid gives bit for bit the results of the C++ DynamicGrid stepped with the
same inputs: tests/python/grid_driver.cpp runs the C++ grid single-threaded and writes every
cycle's inputs and outputs; this test feeds the same inputs (read back from that file) to the
Python grid with OMP_NUM_THREADS=2 and compares masses and particles exactly."""

import os
import subprocess
import tempfile
import unittest

import numpy as np

import dualgrid

DRIVER = os.environ.get("DUALGRID_GRID_DRIVER")


class Reader:
    """Sequential reader of the driver's file (format in grid_driver.cpp)."""

    def __init__(self, path):
        with open(path, "rb") as f:
            self.buf = f.read()
        self.pos = 0

    def take(self, dtype, count):
        a = np.frombuffer(self.buf, dtype=dtype, count=count, offset=self.pos)
        self.pos += a.nbytes
        return a.copy()

    def done(self):
        return self.pos == len(self.buf)


def reference_run(preset, mode, particles, cycles, seed):
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "ref.bin")
        env = dict(os.environ, OMP_NUM_THREADS="1")
        subprocess.run([DRIVER, path, preset, mode, str(particles), str(cycles), str(seed)],
                       check=True, env=env)
        return Reader(path)


@unittest.skipUnless(DRIVER, "DUALGRID_GRID_DRIVER (the python_grid_driver executable) not set")
class IdenticalToCppTest(unittest.TestCase):

    def compare(self, preset, mode, particles=20000, cycles=40, seed=7):
        r = reference_run(preset, mode, particles, cycles, seed)
        self.assertEqual(r.take("S8", 1)[0], b"DGPYREF1")
        n_cycles, nx, ny, n = r.take(np.int32, 4)
        self.assertEqual((n_cycles, n), (cycles, particles))
        params = dualgrid.preset(preset)
        params.mode = mode
        params.num_particles = particles
        params.num_birth = particles // 10
        grid = dualgrid.DynamicGrid(params, seed=seed)
        self.assertEqual((grid.cells_x, grid.cells_y), (nx, ny))
        cells = int(nx) * int(ny)
        dynamic_seen = 0.0
        for k in range(cycles):
            ego = r.take(np.float64, 6)
            det = r.take(np.float64, int(r.take(np.int64, 1)[0]) * 6).reshape(-1, 6)
            cov = r.take(np.float64, int(r.take(np.int64, 1)[0]) * 6).reshape(-1, 6)
            grid.update(ego_pose=ego[:3], ego_velocity=ego[3:5], detections=det, coverage=cov,
                        dt=ego[5])
            m = grid.masses()
            where = f"{preset}/{mode} cycle {k}"
            for key in ("free", "static", "dynamic"):
                expected = r.take(np.float32, cells).reshape(ny, nx)
                # Bit patterns, not values: -0.0 vs 0.0 or a NaN would count as different.
                np.testing.assert_array_equal(m[key].view(np.uint32), expected.view(np.uint32),
                                              err_msg=f"{where} {key}")
            np.testing.assert_array_equal(m["observed"],
                                          r.take(np.uint8, cells).reshape(ny, nx).astype(bool),
                                          err_msg=f"{where} observed")
            p = grid.particles()
            for key, dtype, bits in (("x", np.float64, np.uint64), ("y", np.float64, np.uint64),
                                     ("vx", np.float32, np.uint32), ("vy", np.float32, np.uint32),
                                     ("w_position", np.float32, np.uint32),
                                     ("w_velocity", np.float32, np.uint32),
                                     ("weight", np.float32, np.uint32)):
                np.testing.assert_array_equal(p[key].view(bits), r.take(dtype, n).view(bits),
                                              err_msg=f"{where} particle {key}")
            dynamic_seen = max(dynamic_seen, float(m["dynamic"].max()))
        self.assertTrue(r.done(), "unread data in the reference file")
        # Not a vacuous comparison: the moving car gave some cells dynamic mass (little in the
        # paper's velocity mode, whose eq. (8) cannot follow the car's tangential motion).
        self.assertGreater(dynamic_seen, 0.05)

    def test_dualgrid_preset_dual(self):
        self.compare("dualgrid", "dual")

    def test_paper_preset_each_mode(self):
        for mode in ("position", "velocity", "dual"):
            with self.subTest(mode=mode):
                self.compare("paper", mode, particles=8000, cycles=25, seed=3)


if __name__ == "__main__":
    unittest.main()
