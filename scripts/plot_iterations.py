#!/usr/bin/python3
"""Fig. 2 of the paper: Newton iterations and average GMRES iterations per Newton iteration at each time step.

Usage: /usr/bin/python3 scripts/plot_iterations.py RUN_DIR [-o PNG]
RUN_DIR is the --out directory of `immerse run` (diagnostics.csv columns newton_its and gmres_its, the latter
summed over the step's Newton iterations). Default PNG: RUN_DIR/iterations.png.
"""
import argparse
import os

import matplotlib.pyplot as plt
import numpy as np

import plot_common as pc


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run_dir")
    parser.add_argument("-o", "--output", help="PNG to write (default RUN_DIR/iterations.png)")
    args = parser.parse_args()

    cfg = pc.read_config(args.run_dir)
    diag = pc.read_diagnostics(args.run_dir)
    step = diag["step"]
    newton = diag["newton_its"]
    gmres_per_newton = np.divide(diag["gmres_its"], newton, out=np.zeros_like(newton), where=newton > 0)

    fig, ax = plt.subplots(figsize=(6.4, 3.6))
    ax.plot(step, newton, "o-", ms=3, lw=1, label="Newton iterations")
    ax.plot(step, gmres_per_newton, "s--", ms=3, lw=1, label="GMRES iterations per Newton iteration")
    ax.set_xlabel("time step")
    ax.set_ylabel("iterations per step")
    ax.set_ylim(bottom=0)
    dx = cfg["domain"]["Lx"] / cfg["grid"]["nx"]
    ax.set_title(f"{pc.label_of(cfg, args.run_dir)}, {cfg['grid']['nx']}$^3$ grid, "
                 f"$\\Delta t$ = {cfg['time']['dt'] / dx:g} $\\Delta x$ ({cfg['time']['scheme']})")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    out = args.output or os.path.join(args.run_dir, "iterations.png")
    fig.savefig(out, dpi=pc.DPI)
    print(f"{out}: {len(step)} steps, Newton mean {newton.mean():.2f} max {newton.max():g}, "
          f"GMRES per Newton mean {gmres_per_newton[newton > 0].mean():.2f} max {gmres_per_newton.max():.2f}")


if __name__ == "__main__":
    main()
