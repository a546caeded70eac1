"""The Python module: configurations from files and dicts with `set` keys, stepping and running, diagnostics and
node arrays as numpy arrays, errors as exceptions, and the sweep example. Run by CTest with /usr/bin/python3."""
import math
import os
import subprocess
import sys
import unittest
from pathlib import Path

import numpy as np

import immerse

ROOT = Path(__file__).resolve().parents[2]
QUICK = ROOT / "scenarios" / "capsule_shear_quick.toml"

# A sphere of radius 1 at rest in a periodic box of side 4 (nondimensional units), 16^3 grid, 162 nodes.
SPHERE = {
    "scenario": {"kind": "none"},
    "domain": {"Lx": 4.0, "Ly": 4.0, "Lz": 4.0},
    "grid": {"nx": 16, "ny": 16, "nz": 16},
    "fluid": {"rho": 1.0, "mu": 1.0},
    "time": {"dt": 0.02, "end": 0.1},
    "output": {"fields_every": 0, "checkpoint_every": 0},
    "membrane": [{"shape": "sphere", "radius": 1.0, "center": [2.0, 2.0, 2.0], "Es": 1.0, "mesh.level": 1}],
}


class Module(unittest.TestCase):
    def test_a_file_with_set_keys_means_what_the_keys_say(self):
        config = immerse.load(QUICK, set={"scenario.G": 0.1, "time.scheme": "anderson"})
        d = config.to_dict()
        self.assertEqual(d["scenario"]["G"], 0.1)
        self.assertEqual(d["time"]["scheme"], "anderson")
        as_list = immerse.load(QUICK, set=["scenario.G=0.1", 'time.scheme="anderson"']).to_toml()
        self.assertEqual(as_list, config.to_toml())

    def test_bad_keys_raise_input_error_naming_the_key(self):
        with self.assertRaises(immerse.InputError) as e:
            immerse.load(QUICK, set={"scenario.Gx": 0.1})
        self.assertIn("scenario.Gx", str(e.exception))
        self.assertIsInstance(e.exception, ValueError)
        with self.assertRaises(ValueError) as e:
            immerse.load(dict(SPHERE, grid={"nx": -4}))
        self.assertIn("grid.nx", str(e.exception))
        with self.assertRaises(ValueError) as e:
            immerse.load(dict(SPHERE, fluid={"mu": object()}))
        self.assertIn("fluid.mu", str(e.exception))

    def test_a_sphere_at_rest_stays_at_rest_and_keeps_its_volume(self):
        sim = immerse.Simulation(immerse.load(SPHERE))
        X0 = sim.positions()
        self.assertEqual(X0.shape, (162, 3))
        self.assertEqual(X0.dtype, np.float64)
        rows = sim.run()
        self.assertTrue(sim.finished)
        self.assertEqual(list(rows["step"]), [1, 2, 3, 4, 5])
        self.assertAlmostEqual(sim.time, 0.1, places=12)
        self.assertEqual(set(rows), set(sim.columns))
        self.assertEqual(list(sim.units), sim.columns)
        self.assertEqual((sim.units["time"], sim.units["volume"], sim.units["theta"]), ("s", "m^3", "rad"))
        # No force, no flow: nodes and volume unchanged to round-off.
        self.assertLess(np.abs(sim.positions() - X0).max(), 1e-12)
        self.assertLess(np.abs(sim.velocities()).max(), 1e-12)
        self.assertLess(abs(rows["volume"][-1] / rows["volume"][0] - 1), 1e-12)
        # Nor energy: no kinetic energy, no strain at the reference shape (round-off of E_s times the area, 12.6 J),
        # nothing to account for.
        self.assertLess(np.abs(rows["E_kinetic"]).max(), 1e-24)
        self.assertLess(np.abs(rows["E_elastic"]).max(), 1e-14)
        self.assertLess(np.abs(rows["budget_residual"]).max(), 1e-24)

    def test_stepping_and_running_give_the_same_run(self):
        config = immerse.load(QUICK, set={"scenario.kt_end": 0.25})
        a = immerse.Simulation(config)
        stepped = [a.step() for _ in range(5)]
        b = immerse.Simulation(config)
        ran = b.run(steps=3)
        ran2 = b.run(until=5 * stepped[0]["dt"] * 0.999)
        self.assertEqual(len(ran["step"]) + len(ran2["step"]), 5)
        self.assertTrue(np.array_equal(a.positions(), b.positions()))
        self.assertEqual(stepped[-1]["D_xz"], ran2["D_xz"][-1])
        self.assertGreater(stepped[-1]["D_xz"], 0)
        self.assertEqual(stepped[-1]["rejected"], 0)

    def test_every_row_carries_the_energy_budget(self):
        # The capsule in shear between sliding walls: the walls put power into the fluid, which dissipates it; the
        # budget's residual is E_total - E_total(t0) + the trapezoidal integral of dissipation - P_walls - P_body.
        sim = immerse.Simulation(immerse.load(QUICK, set={"scenario.kt_end": 0.25}))
        rows = sim.run(steps=4)
        units = sim.units
        self.assertEqual([units[c] for c in ("E_kinetic", "dissipation", "P_walls", "P_body", "E_elastic",
                                             "E_bending", "E_constraint", "E_total", "budget_residual")],
                         ["J", "W", "W", "W", "J", "J", "J", "J", "J"])
        self.assertEqual(sim.columns[-2:], ["E_total", "budget_residual"])
        self.assertTrue(np.all(rows["P_walls"] > 0))
        self.assertTrue(np.all(rows["dissipation"] > 0))
        self.assertTrue(np.all(rows["P_body"] == 0))
        np.testing.assert_allclose(rows["E_total"], rows["E_kinetic"] + rows["E_elastic"] + rows["E_bending"]
                                   + rows["E_constraint"], rtol=1e-14)
        rate = rows["dissipation"] - rows["P_walls"] - rows["P_body"]
        integral = np.concatenate([[0.0], np.cumsum(0.5 * rows["dt"][1:] * (rate[1:] + rate[:-1]))])
        expected = rows["E_total"] - rows["E_total"][0] + integral + rows["budget_residual"][0]
        scale = np.abs(rows["P_walls"]).max() * rows["time"][-1]
        np.testing.assert_allclose(rows["budget_residual"], expected, rtol=0, atol=1e-12 * scale)

    def test_applied_forces_move_the_membrane(self):
        sim = immerse.Simulation(immerse.load(SPHERE))
        X = sim.positions()
        F = np.zeros_like(X)
        F[:, 0] = 1e-2 * np.sign(X[:, 0] - 2.0)  # pull the two halves apart along x
        sim.set_applied_forces(0, F)
        rows = sim.run(steps=3)
        self.assertGreater(rows["a1"][-1], rows["a2"][-1])
        with self.assertRaises(ValueError):
            sim.set_applied_forces(0, F[:10])
        with self.assertRaises(IndexError):
            sim.positions(3)

    def test_the_sweep_example_runs_and_deformation_grows_with_g(self):
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
        p = subprocess.run([sys.executable, str(ROOT / "python" / "examples" / "sweep_G.py"), "0.5", "0.05", "0.1"],
                           env=env, capture_output=True, text=True, check=True)
        lines = p.stdout.strip().splitlines()
        d = [float(line.split()[1]) for line in lines[1:]]
        self.assertEqual(len(d), 2)
        self.assertTrue(all(math.isfinite(x) and x > 0 for x in d))
        self.assertGreater(d[1], d[0])


if __name__ == "__main__":
    unittest.main()
