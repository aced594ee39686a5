"""Installation as Python users expect it (docs/python.md, "Installation"):
- the installed package imports in a virtual environment made with --system-site-packages
  (Debian's numpy);
- `pip install --no-build-isolation .` from the repository builds the module with CMake and
  Debian's tools into such a venv, and the result runs a co-simulation from another folder
  without PYTHONPATH (its networks inside the package);
- imported by an interpreter it was not built for, the package names the one it was built for.

Needs DUALGRID_SOURCE_DIR; PYTHONPATH is the installed package (tests/python). The pip build
compiles the libraries again (ccache is used when on PATH): minutes."""

import os
import shutil
import subprocess
import sys
import tempfile
import unittest

import dualgrid

SOURCE = os.environ.get("DUALGRID_SOURCE_DIR", ".")
SCENARIO = os.path.join(SOURCE, "scenarios", "simple_road.yaml")
SMOKE = ("import dualgrid, sys; "
         f"r = dualgrid.CoSimulation({SCENARIO!r}, duration=0.5, modes=['dual']).run(); "
         "print(dualgrid.__file__, r['steps'], dualgrid._build_info.BUILT_FOR)")


def run(cmd, env=None, cwd=None):
    return subprocess.run(cmd, env=env, cwd=cwd, capture_output=True, text=True)


class InstallTest(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.venv = os.path.join(cls.tmp.name, "venv")
        subprocess.run([sys.executable, "-m", "venv", "--system-site-packages", cls.venv],
                       check=True)
        cls.python = os.path.join(cls.venv, "bin", "python")
        cls.clean_env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_installed_package_in_a_venv(self):
        r = run([self.python, "-c", SMOKE], env=os.environ, cwd=self.tmp.name)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn(" 10 ", r.stdout)

    def test_pip_install_into_a_venv(self):
        env = dict(self.clean_env, DUALGRID_PIP_BUILD_DIR=os.path.join(self.tmp.name, "cmake"),
                   CMAKE_BUILD_PARALLEL_LEVEL="2", PIP_NO_INDEX="1")
        if shutil.which("ccache"):
            env["DUALGRID_CMAKE_ARGS"] = ("-DCMAKE_CXX_COMPILER_LAUNCHER=ccache "
                                          "-DCMAKE_C_COMPILER_LAUNCHER=ccache")
        r = run([self.python, "-m", "pip", "install", "--no-build-isolation", SOURCE], env=env)
        self.assertEqual(r.returncode, 0, r.stdout[-3000:] + r.stderr[-3000:])
        # From another folder, without PYTHONPATH: the venv's own copy, networks included.
        r = run([self.python, "-c", SMOKE], env=self.clean_env, cwd=self.tmp.name)
        self.assertEqual(r.returncode, 0, r.stderr)
        file, steps, built_for = r.stdout.split()
        self.assertTrue(file.startswith(self.venv), file)
        self.assertEqual(steps, "10")
        self.assertEqual(built_for, self.python)
        r = run([self.python, "-m", "pip", "uninstall", "-y", "dualgrid"], env=self.clean_env)
        self.assertEqual(r.returncode, 0, r.stderr)

    def test_another_interpreter_is_named(self):
        # No site-packages: no numpy. The message names this interpreter and the one built for.
        r = run([sys.executable, "-S", "-c", "import dualgrid"], env=os.environ)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("dualgrid needs numpy", r.stderr)
        self.assertIn(f"this interpreter, {sys.executable}", r.stderr)
        self.assertIn(f"built for {dualgrid._build_info.BUILT_FOR}", r.stderr)
        # An extension for another Python version: a copy of the package whose module carries
        # another version's suffix, as a package built for Python 3.9 would.
        pkg = os.path.join(self.tmp.name, "other", "dualgrid")
        shutil.copytree(os.path.dirname(dualgrid.__file__), pkg,
                        ignore=shutil.ignore_patterns("__pycache__", "networks"))
        so = [f for f in os.listdir(pkg) if f.startswith("_dualgrid.") and f.endswith(".so")]
        self.assertEqual(len(so), 1)
        os.rename(os.path.join(pkg, so[0]),
                  os.path.join(pkg, "_dualgrid.cpython-39-x86_64-linux-gnu.so"))
        env = dict(os.environ, PYTHONPATH=os.path.dirname(pkg))
        r = run([sys.executable, "-c", "import dualgrid"], env=env)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("compiled module did not load", r.stderr)
        self.assertIn("_dualgrid.cpython-39-x86_64-linux-gnu.so", r.stderr)
        self.assertIn(f"built for {dualgrid._build_info.BUILT_FOR}", r.stderr)


if __name__ == "__main__":
    unittest.main()
