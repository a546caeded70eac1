"""scripts/plot_suspension_shear.py: Pries et al.'s (1992) fit at its defining points, and the window mean and block
standard error of a synthetic run folder, plotted end to end. Run by CTest with /usr/bin/python3."""
import os
import subprocess
import sys
import tempfile
import unittest

import numpy as np

SCRIPTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts")
sys.path.insert(0, SCRIPTS)
import plot_suspension_shear as pss  # noqa: E402

CONFIG = """[scenario]
kind = "suspension_shear"
[domain]
Lx = 2.4e-5
Ly = 2.4e-5
Lz = 2.4e-5
[grid]
nx = 32
ny = 32
nz = 32
[boundary]
z_lower_velocity = [-1.2e-2, 0.0, 0.0]
z_upper_velocity = [1.2e-2, 0.0, 0.0]
[[membrane]]
viscosity_ratio = 5.0
mesh.family = "icosahedral"
mesh.level = 3
"""


def write_run(folder, H, eta):
    os.makedirs(folder)
    with open(os.path.join(folder, "config.resolved.toml"), "w") as f:
        f.write(CONFIG)
    kt = np.linspace(0, 2, len(eta))
    with open(os.path.join(folder, "diagnostics.csv"), "w") as f:
        f.write("step,time,kt,volume_fraction,relative_viscosity\n")
        for i, (t, e) in enumerate(zip(kt, eta)):
            f.write(f"{i},{t / 1000},{t},{H},{e}\n")


class Pries(unittest.TestCase):
    def test_defining_points(self):
        self.assertAlmostEqual(pss.pries(0.0, np.inf), 1.0, places=14)
        self.assertAlmostEqual(pss.pries(0.45, np.inf), 3.2, places=14)
        # eta_045(24 um) = 220 e^-31.2 + 3.2 - 2.44 exp(-0.06 * 24^0.645)
        self.assertAlmostEqual(pss.pries(0.45, 24.0), 220 * np.exp(-31.2) + 3.2 - 2.44 * np.exp(-0.06 * 24.0 ** 0.645),
                               places=14)
        self.assertAlmostEqual(pss.pries(0.2, np.inf), 1 + 2.2 * (0.8 ** -0.8 - 1) / (0.55 ** -0.8 - 1), places=14)
        h = np.linspace(0, 0.45, 10)
        self.assertTrue(np.all(np.diff(pss.pries(h, 24.0)) > 0))
        self.assertTrue(np.all(pss.pries(h[1:], 24.0) < pss.pries(h[1:], np.inf)))


class RunFolder(unittest.TestCase):
    def test_window_mean_block_error_and_plot(self):
        with tempfile.TemporaryDirectory() as tmp:
            # a transient, then 1.5 + alternating blocks of +-0.01 over the second half (k t >= 1)
            eta = np.concatenate([np.linspace(1, 1.5, 20), 1.5 + 0.01 * np.repeat([1, -1, 1, -1], 5)])
            write_run(os.path.join(tmp, "a"), 0.1, np.concatenate([[1.0], eta]))
            run = pss.read_run(os.path.join(tmp, "a"), None)
            self.assertAlmostEqual(run["start"], 1.0)
            # k t = 1, 1.05, ..., 2: trapezoidal weights 1/2 at the ends; blocks of 0.25 in k t
            window = np.concatenate([[1.0], eta])[np.linspace(0, 2, 41) >= 1.0 - 1e-12]
            w = np.full(len(window), 0.05)
            w[0] = w[-1] = 0.025
            self.assertAlmostEqual(run["mean"], np.sum(w * window) / np.sum(w), places=12)
            self.assertGreater(run["sem"], 0.0)
            self.assertLess(run["sem"], 0.01)
            write_run(os.path.join(tmp, "b"), 0.3, np.full(41, 2.5))
            out = os.path.join(tmp, "s.png")
            r = subprocess.run([sys.executable, os.path.join(SCRIPTS, "plot_suspension_shear.py"),
                                os.path.join(tmp, "a"), os.path.join(tmp, "b"), "-o", out],
                               capture_output=True, text=True)
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertTrue(os.path.getsize(out) > 0)
            self.assertIn("H = 0.3000", r.stdout)
            self.assertIn("eta_rel = 2.5000 +- 0.0000", r.stdout)

    def test_other_scenarios_are_refused(self):
        with tempfile.TemporaryDirectory() as tmp:
            write_run(os.path.join(tmp, "a"), 0.1, np.ones(20))
            path = os.path.join(tmp, "a", "config.resolved.toml")
            with open(path) as f:
                text = f.read().replace("suspension_shear", "custom")
            with open(path, "w") as f:
                f.write(text)
            with self.assertRaises(SystemExit) as e:
                pss.read_run(os.path.join(tmp, "a"), None)
            self.assertIn("not 'suspension_shear'", str(e.exception.code))


if __name__ == "__main__":
    unittest.main()
