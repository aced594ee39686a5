"""Executes docs/examples/notebooks/crossing.ipynb headless (`jupyter nbconvert --execute`,
Debian's jupyter-nbconvert and python3-ipykernel) and checks what it shows: no error, the three
modes' D_v printed, and its two figures (the grid and detections at three times; the modes
compared) present as PNGs that decode, are of figure size and are not blank (ctest
python_notebook). Needs DUALGRID_EXE and the installed package on PYTHONPATH (tests/python)."""

import base64
import io
import os
import subprocess
import sys
import tempfile
import unittest

import matplotlib.image as mpimg
import nbformat
import numpy as np

NOTEBOOK = os.path.join(os.environ.get("DUALGRID_SOURCE_DIR", "."), "docs", "examples",
                        "notebooks", "crossing.ipynb")


class NotebookTest(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        env = {k: v for k, v in os.environ.items() if k != "MPLBACKEND"}  # the inline backend
        r = subprocess.run([sys.executable, "-m", "jupyter", "nbconvert", "--to", "notebook",
                            "--execute", "--ExecutePreprocessor.timeout=1500",
                            "--output-dir", cls.tmp.name, NOTEBOOK],
                           env=env, capture_output=True, text=True)
        if r.returncode != 0:
            raise AssertionError("nbconvert failed:\n" + r.stderr[-4000:])
        cls.nb = nbformat.read(os.path.join(cls.tmp.name, os.path.basename(NOTEBOOK)), 4)
        cls.outputs = [o for c in cls.nb.cells if c.cell_type == "code" for o in c.outputs]

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_no_error_and_dv_of_three_modes(self):
        self.assertFalse([o for o in self.outputs if o.output_type == "error"])
        text = "".join(o.get("text", "") for o in self.outputs if o.output_type == "stream")
        for mode in ("position", "velocity", "dual"):
            line = [ln for ln in text.splitlines() if ln.startswith(mode)]
            self.assertEqual(len(line), 1, text)
            dv = float(line[0].split()[1])
            self.assertTrue(0.0 <= dv <= 1.0, line)

    def test_figures_exist_and_are_not_empty(self):
        pngs = [o["data"]["image/png"] for o in self.outputs
                if o.output_type in ("display_data", "execute_result") and "image/png" in o.get("data", {})]
        self.assertEqual(len(pngs), 2)
        for b64 in pngs:
            raw = base64.b64decode(b64)
            self.assertTrue(raw.startswith(b"\x89PNG\r\n\x1a\n"))
            img = mpimg.imread(io.BytesIO(raw), format="png")
            h, w = img.shape[:2]
            self.assertGreater(w, 300)
            self.assertGreater(h, 200)
            # Not blank: drawn pixels vary, and more than a few colours are used.
            self.assertGreater(float(np.std(img[..., :3])), 0.05)
            self.assertGreater(len(np.unique(img[..., :3].reshape(-1, 3), axis=0)), 50)


if __name__ == "__main__":
    unittest.main()
