"""Hostile use of the Python module: wrong types, NaN, arrays of the wrong shape, a simulation
used after it ended, after an error, or from two threads at once, two SUMO runs at once. Every
case must raise a Python exception with a message naming what was wrong, never crash the
interpreter (each case runs in this one process, so a crash fails the whole script).

Needs DUALGRID_SOURCE_DIR; run against the installed package (tests/python)."""

import math
import os
import threading
import unittest

import numpy as np

import dualgrid

SCENARIO = os.path.join(os.environ.get("DUALGRID_SOURCE_DIR", "."), "scenarios", "simple_road.yaml")


def short_sim(**kw):
    kw.setdefault("duration", 0.5)
    kw.setdefault("modes", ["dual"])
    return dualgrid.CoSimulation(SCENARIO, seed=1, **kw)


class SimulationMisuseTest(unittest.TestCase):

    def test_wrong_types(self):
        with self.assertRaises(TypeError):
            dualgrid.CoSimulation(42)
        with self.assertRaises(TypeError):
            dualgrid.CoSimulation(SCENARIO, modes="dual", seed="one")
        with self.assertRaises(TypeError):
            dualgrid.CoSimulation(SCENARIO, duration="long")
        with self.assertRaisesRegex(ValueError, "unknown mode 'fast'"):
            dualgrid.CoSimulation(SCENARIO, modes=["fast"])
        with self.assertRaisesRegex(ValueError, "modes must not be empty"):
            dualgrid.CoSimulation(SCENARIO, modes=[])
        with self.assertRaisesRegex(TypeError, "No constructor|Base of|cannot be instantiated"):
            dualgrid.Simulation()

    def test_bad_seeds(self):
        # Every entry point with a seed: one line naming it, ValueError out of [0, 2**64 - 1],
        # TypeError for a non-integer (bool too); the largest seed is accepted.
        # The arguments are converted before anything is read: a missing sequence folder is
        # never reached.
        radarscenes = "no/such/sequence"
        makers = {
            "CoSimulation": lambda s: dualgrid.CoSimulation(SCENARIO, seed=s, duration=0.1),
            "run_scenario": lambda s: dualgrid.run_scenario(SCENARIO, seed=s, duration=0.1),
            "DynamicGrid": lambda s: dualgrid.DynamicGrid(seed=s),
            "RadarModel": lambda s: dualgrid.RadarModel([dualgrid.SensorParams()], seed=s),
            "run_recorded": lambda s: dualgrid.run_recorded(radarscenes, seed=s),
            "RecordedSimulation": lambda s: dualgrid.RecordedSimulation(radarscenes, seed=s),
        }
        for name, make in makers.items():
            for bad, error in [(-1, ValueError), (2**64, ValueError), (-2**70, ValueError),
                               (1.5, TypeError), (True, TypeError), ("1", TypeError)]:
                with self.subTest(entry=name, seed=bad):
                    with self.assertRaises(error) as caught:
                        make(bad)
                    text = str(caught.exception)
                    self.assertRegex(text, r"^seed: expected an integer in \[0, 2\*\*64 - 1\]")
                    self.assertNotIn("\n", text)
        self.assertEqual(dualgrid.RadarModel([dualgrid.SensorParams()], seed=2**64 - 1).seed,
                         2**64 - 1)
        dualgrid.DynamicGrid(seed=2**64 - 1)

    def test_nan_and_bad_values(self):
        with self.assertRaisesRegex(ValueError, "duration must be in"):
            dualgrid.CoSimulation(SCENARIO, duration=math.nan)
        with self.assertRaisesRegex(ValueError, "duration must be in"):
            dualgrid.CoSimulation(SCENARIO, duration=-1.0)
        with self.assertRaisesRegex(ValueError, "filter.sigma_v"):
            dualgrid.CoSimulation(SCENARIO, overrides=["filter.sigma_v=nan"])
        with self.assertRaisesRegex(ValueError, "threads must be >= 0"):
            dualgrid.CoSimulation(SCENARIO, threads=-2)
        with self.assertRaisesRegex(ValueError, "not found"):
            dualgrid.CoSimulation("no/such/scenario.yaml")

    def test_after_the_end(self):
        sim = short_sim()
        steps = list(sim)
        self.assertEqual(len(steps), 10)
        self.assertEqual(sim.state, "ended")
        self.assertEqual(list(sim), [])  # an ended iterator stays ended
        with self.assertRaisesRegex(RuntimeError, "has ended after 10 steps"):
            sim.step()
        self.assertEqual(sim.results()["steps"], 10)
        sim.close()  # no-op
        # The steps' arrays outlive the simulation.
        del sim
        self.assertEqual(steps[3].grids["dual"].masses.shape[2], 3)

    def test_step_returns_none_once_then_raises(self):
        sim = short_sim()
        n = 0
        while sim.step() is not None:
            n += 1
        self.assertEqual(n, 10)
        with self.assertRaisesRegex(RuntimeError, "ended"):
            sim.step()

    def test_results_before_the_end_and_close(self):
        with short_sim(duration=2.0) as sim:
            sim.step()
            with self.assertRaisesRegex(RuntimeError, r"has not ended \(1 steps done\)"):
                sim.results()
            self.assertEqual(sim.metrics()["dual"]["frames"], 1)
        self.assertEqual(sim.state, "closed")
        r = sim.results()
        self.assertEqual(r["steps"], 1)
        self.assertFalse(r["complete"])
        with self.assertRaisesRegex(RuntimeError, "been closed"):
            sim.step()

    def test_after_an_error(self):
        sim = short_sim()
        next(sim)
        sim._fail_next_step()
        with self.assertRaisesRegex(RuntimeError, "failure injected"):
            next(sim)
        self.assertEqual(sim.state, "failed")
        for call in (sim.step, sim.results, sim.metrics, sim.run, lambda: next(sim)):
            with self.assertRaisesRegex(RuntimeError, "unusable after an error in step 1"):
                call()
        # SUMO was released: a new simulation runs.
        self.assertEqual(short_sim().run()["steps"], 10)

    def test_two_sumo_runs_at_once(self):
        first = short_sim()
        with self.assertRaisesRegex(RuntimeError, "another SUMO co-simulation is running"):
            short_sim()
        with self.assertRaisesRegex(RuntimeError, "another SUMO co-simulation is running"):
            dualgrid.run_scenario(SCENARIO, duration=0.5, modes=["dual"])
        first.close()
        self.assertEqual(short_sim().run()["steps"], 10)
        # An abandoned simulation releases SUMO when it is collected.
        abandoned = short_sim()
        next(abandoned)
        del abandoned
        self.assertEqual(short_sim().run()["steps"], 10)

    def test_two_threads_on_one_simulation(self):
        sim = short_sim(duration=20.0, modes=["position", "velocity", "dual"])
        started = threading.Event()
        errors = []

        def runner():
            started.set()
            try:
                sim.run()
            except Exception as e:  # noqa: BLE001 (reported below)
                errors.append(e)

        t = threading.Thread(target=runner)
        t.start()
        started.wait()
        while sim.steps == 0 and t.is_alive():  # steps is readable while another thread runs
            t.join(0.01)
        busy = []
        # The runner holds the simulation for seconds; every call meanwhile is refused.
        while t.is_alive() and len(busy) < 3:
            try:
                sim.step()
            except RuntimeError as e:
                busy.append(str(e))
            t.join(0.05)
        t.join()
        self.assertEqual(errors, [])
        self.assertTrue(busy, "the second thread was never refused")
        self.assertIn("busy in another thread", busy[0])
        self.assertEqual(sim.results()["steps"], 400)


if __name__ == "__main__":
    unittest.main()
