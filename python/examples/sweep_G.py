#!/usr/bin/python3
"""A parameter sweep from Python: the quick capsule in shear (scenarios/capsule_shear_quick.toml) at several
capillary numbers G, each run to k t = KT, and the Taylor deformation D_xz and inclination at its end.

    PYTHONPATH=build/release/python /usr/bin/python3 python/examples/sweep_G.py [KT] [G ...]

Defaults: KT = 6 (the scenario's end), G = 0.025 0.05 0.1.
"""
import sys
from pathlib import Path

import immerse

SCENARIO = Path(__file__).resolve().parents[2] / "scenarios" / "capsule_shear_quick.toml"


def sweep(gs, kt_end):
    """{G: (D_xz, theta in rad)} at k t = kt_end."""
    out = {}
    for g in gs:
        config = immerse.load(SCENARIO, set={"scenario.G": g, "scenario.kt_end": kt_end})
        rows = immerse.Simulation(config).run()
        out[g] = (float(rows["D_xz"][-1]), float(rows["theta"][-1]))
    return out


if __name__ == "__main__":
    kt = float(sys.argv[1]) if len(sys.argv) > 1 else 6.0
    gs = [float(g) for g in sys.argv[2:]] or [0.025, 0.05, 0.1]
    print(f"{'G':>8} {'D_xz':>10} {'theta/pi':>10}   (k t = {kt:g})")
    for g, (d, theta) in sweep(gs, kt).items():
        print(f"{g:8.4g} {d:10.5f} {theta / 3.141592653589793:10.5f}")
