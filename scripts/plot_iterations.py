#!/usr/bin/python3
"""Fig. 2 of the paper: Newton iterations and average GMRES iterations per Newton iteration at each time step.

Usage: /usr/bin/python3 scripts/plot_iterations.py RUN_DIR [RUN_DIR ...] [-o PNG]
RUN_DIR is the --out directory of `immerse run` (diagnostics.csv columns newton_its and gmres_its, the latter
summed over the step's Newton iterations). Several runs (e.g. dt = dx and dt = 4 dx, Fig. 2 a and b) give one panel
each, side by side. Default PNG: iterations.png in the first RUN_DIR.
"""
import argparse
import os

import matplotlib.pyplot as plt
import numpy as np

import plot_common as pc


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run_dirs", nargs="+", metavar="RUN_DIR")
    parser.add_argument("-o", "--output", help="PNG to write (default iterations.png in the first RUN_DIR)")
    args = parser.parse_args()

    n = len(args.run_dirs)
    fig, axes = plt.subplots(1, n, figsize=(6.4 * n, 3.6), squeeze=False)
    for col, (ax, run_dir) in enumerate(zip(axes[0], args.run_dirs)):
        cfg = pc.read_config(run_dir)
        diag = pc.read_diagnostics(run_dir)
        step = diag["step"]
        newton = diag["newton_its"]
        gmres_per_newton = np.divide(diag["gmres_its"], newton, out=np.zeros_like(newton), where=newton > 0)
        # Long runs as markers only: lines between steps of 0 and 1 iterations would fill the panel.
        many = len(step) > 200
        ax.plot(step, newton, "o" if many else "o-", ms=2.5 if many else 3, lw=1, label="Newton iterations")
        ax.plot(step, gmres_per_newton + (0.08 if many else 0.0), "s" if many else "s--", ms=2.5 if many else 3,
                lw=1, mfc="none", label="GMRES iterations per Newton iteration" + (" (+0.08)" if many else ""))
        ax.set_xlabel("time step")
        ax.set_ylabel("iterations per step")
        ax.set_ylim(bottom=0)
        dx = cfg["domain"]["Lx"] / cfg["grid"]["nx"]
        panel = f"({chr(ord('a') + col)}) " if n > 1 else ""
        ax.set_title(f"{panel}{pc.label_of(cfg, run_dir)}, {cfg['grid']['nx']}$^3$ grid, "
                     f"$\\Delta t$ = {cfg['time']['dt'] / dx:g} $\\Delta x$ ({cfg['time']['scheme']})", fontsize=10)
        ax.grid(alpha=0.3)
        ax.legend()
        print(f"{run_dir}: dt = {cfg['time']['dt'] / dx:g} dx, {len(step)} steps, Newton mean {newton.mean():.2f} "
              f"max {newton.max():g}, GMRES per Newton mean {gmres_per_newton[newton > 0].mean():.2f} "
              f"max {gmres_per_newton.max():.2f}")
    fig.tight_layout()
    out = args.output or os.path.join(args.run_dirs[0], "iterations.png")
    fig.savefig(out, dpi=pc.DPI)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
