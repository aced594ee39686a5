"""The typing stubs against Debian's mypy (ctest python_stubs): the package passes mypy --strict,
a typed use of the API passes, six wrong uses are each rejected, and stubtest finds no
difference between the stub and the module beyond pybind11's own (typing/stubtest_allowlist.txt).

Run against the installed package (PYTHONPATH, as every test of tests/python)."""

import os
import re
import subprocess
import sys
import unittest

HERE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "typing")


def mypy(*args):
    r = subprocess.run([sys.executable, "-m", "mypy", "--no-incremental", "--strict",
                        "--ignore-missing-imports", *args], capture_output=True, text=True)
    return r.returncode, r.stdout + r.stderr


class StubsTest(unittest.TestCase):

    def test_package_passes_strict(self):
        rc, out = mypy("-p", "dualgrid")
        self.assertEqual(rc, 0, out)

    def test_typed_use_passes(self):
        rc, out = mypy(os.path.join(HERE, "usage.py"))
        self.assertEqual(rc, 0, out)

    def test_wrong_uses_are_rejected(self):
        path = os.path.join(HERE, "misuse.py")
        rc, out = mypy(path)
        self.assertNotEqual(rc, 0)
        with open(path) as f:
            expected = {i + 1 for i, line in enumerate(f) if "# E:" in line}
        found = {int(m) for m in re.findall(r"misuse\.py:(\d+): error", out)}
        self.assertEqual(found, expected, out)

    def test_stub_matches_the_module(self):
        r = subprocess.run([sys.executable, "-m", "mypy.stubtest", "dualgrid", "--concise",
                            "--allowlist", os.path.join(HERE, "stubtest_allowlist.txt")],
                           capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)


if __name__ == "__main__":
    unittest.main()
