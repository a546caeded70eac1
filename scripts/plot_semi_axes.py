#!/usr/bin/python3
"""Figs. 4-5 of the paper: the principal semi-axes a1, a2, a3 of the membrane's equivalent ellipsoid vs time
(a1, a2, a3: the principal axes nearest to x, y and z, so each curve follows one axis of the shape).

Usage: /usr/bin/python3 scripts/plot_semi_axes.py RUN_DIR [-o PNG] [--membrane I]
For the oscillating membrane of §4.1 (scenario.kind = "oscillating_membrane") the equilibrium sphere of radius
(abc)^(1/3) = (0.25 * 0.22 * 0.2)^(1/3) = 0.2224 is drawn dashed. Default PNG: RUN_DIR/semi_axes.png.
The axes are sorted by length, so when two of them cross the curves swap (a kink), unlike the paper's fixed axes.
"""
import argparse
import os

import matplotlib.pyplot as plt

import plot_common as pc


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run_dir")
    parser.add_argument("-o", "--output", help="PNG to write (default RUN_DIR/semi_axes.png)")
    parser.add_argument("--membrane", type=int, default=0, help="membrane index (default 0)")
    args = parser.parse_args()

    cfg = pc.read_config(args.run_dir)
    diag = pc.read_diagnostics(args.run_dir)
    t = diag["time"]
    oscillating = cfg.get("scenario", {}).get("kind") == "oscillating_membrane"
    # §4.1 is in the paper's nondimensional units (unit box): lengths in box sides L, time in its time unit.
    length_unit, time_unit = (" / L", "") if oscillating else (" (m)", " (s)")

    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    for name, axis, style in (("a1", "x", "-"), ("a2", "y", "--"), ("a3", "z", "-.")):
        ax.plot(t, pc.membrane_column(diag, name, args.membrane), style, lw=1.5, label=f"{name} (along {axis})")
    summary = ""
    if oscillating:
        a, b, c = cfg["membrane"][args.membrane]["semi_axes"]
        r_eq = (a * b * c) ** (1.0 / 3.0)
        ax.axhline(r_eq, color="k", ls=":", lw=1, label=f"$(abc)^{{1/3}}$ = {r_eq:.4f}")
        summary = f", equilibrium {r_eq:.4f}"
    ax.set_xlabel("time t" + time_unit)
    ax.set_ylabel("semi-axes a1, a2, a3" + length_unit)
    ax.set_title(f"Semi-axes of the membrane, {pc.label_of(cfg, args.run_dir)}")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    out = args.output or os.path.join(args.run_dir, "semi_axes.png")
    fig.savefig(out, dpi=pc.DPI)
    final = [pc.membrane_column(diag, n, args.membrane)[-1] for n in ("a1", "a2", "a3")]
    print(f"{out}: t = {t[-1]:g}, final a1, a2, a3 = {final[0]:.4f}, {final[1]:.4f}, {final[2]:.4f}{summary}")


if __name__ == "__main__":
    main()
