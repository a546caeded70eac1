#!/usr/bin/python3
"""Fig. 7 of the paper: the Taylor shape parameter D_xz = (L - B)/(L + B) vs k t, for one or several runs.

Usage: /usr/bin/python3 scripts/plot_taylor.py RUN_DIR [RUN_DIR ...] [-o PNG] [--membrane I] [--theta]
The shear rate is k = (boundary.z_upper_velocity[0] - boundary.z_lower_velocity[0]) / domain.Lz and
G = scenario.G, both from each run's config.resolved.toml. Each run gets the small-deformation theory
D = 25G/4 (numerics notes; neo-Hookean, viscosity ratio 1) as a dashed line of its colour. With --theta a second
panel shows the inclination theta against its small-deformation value pi/4 - 97G/16.
Default PNG: taylor.png in the first RUN_DIR.
"""
import argparse
import os

import matplotlib.pyplot as plt
import numpy as np

import plot_common as pc


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run_dirs", nargs="+", metavar="RUN_DIR")
    parser.add_argument("-o", "--output", help="PNG to write (default taylor.png in the first RUN_DIR)")
    parser.add_argument("--membrane", type=int, default=0, help="membrane index (default 0)")
    parser.add_argument("--theta", action="store_true", help="add a panel with the inclination theta")
    args = parser.parse_args()

    runs = []
    for run_dir in args.run_dirs:
        cfg = pc.read_config(run_dir)
        if "G" not in cfg.get("scenario", {}):
            pc.fail(f"{run_dir}: config.resolved.toml has no scenario.G")
        k = pc.shear_rate(cfg)
        if k == 0.0:
            pc.fail(f"{run_dir}: the z walls do not move (k = 0): not a shear run")
        runs.append((cfg["scenario"]["G"], run_dir, cfg, k))
    runs.sort(key=lambda r: r[0])

    if args.theta:
        fig, (ax, ax_theta) = plt.subplots(1, 2, figsize=(11.0, 4.4))
    else:
        fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for i, (G, run_dir, cfg, k) in enumerate(runs):
        diag = pc.read_diagnostics(run_dir)
        kt = k * diag["time"]
        D = pc.membrane_column(diag, "D_xz", args.membrane)
        theta = pc.membrane_column(diag, "theta", args.membrane)
        color = f"C{i}"
        ax.plot(kt, D, "-", color=color, lw=1.5, label=f"G = {G:g}")
        ax.axhline(25.0 * G / 4.0, color=color, ls="--", lw=1)
        if args.theta:
            ax_theta.plot(kt, theta, "-", color=color, lw=1, label=f"G = {G:g}")
            ax_theta.axhline(np.pi / 4 - 97.0 * G / 16.0, color=color, ls="--", lw=1)
        print(f"{run_dir}: G = {G:g}, k = {k:g} 1/s, kt_end = {kt[-1]:.3g}: D_xz = {D[-1]:.4f} "
              f"(25G/4 = {25 * G / 4:.4f}, ratio {D[-1] / (25 * G / 4):.3f}), theta = {theta[-1]:.4f} rad "
              f"(pi/4 - 97G/16 = {np.pi / 4 - 97 * G / 16:.4f})")
    ax.plot([], [], "k--", lw=1, label="small-deformation theory 25G/4")
    ax.set_xlabel("dimensionless time k t")
    ax.set_ylabel("Taylor parameter $D_{xz}$")
    ax.set_xlim(left=0)
    ax.set_ylim(bottom=0)
    ax.set_title("Initially spherical neo-Hookean capsule in simple shear")
    ax.grid(alpha=0.3)
    ax.legend(loc="lower right", fontsize="small")
    if args.theta:
        ax_theta.plot([], [], "k--", lw=1, label="theory $\\pi/4 - 97G/16$")
        ax_theta.set_xlabel("dimensionless time k t")
        ax_theta.set_ylabel("inclination $\\theta$ (rad)")
        ax_theta.set_xlim(left=0)
        ax_theta.set_title("Inclination of the long axis to the flow")
        ax_theta.grid(alpha=0.3)
        ax_theta.legend(fontsize="small")
    fig.tight_layout()
    out = args.output or os.path.join(args.run_dirs[0], "taylor.png")
    fig.savefig(out, dpi=pc.DPI)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
