#!/usr/bin/python3
"""Two capsules crossing in simple shear: the relative trajectory of their centroids (Lac, Morel & Barthes-Biesel 2007).

Usage: /usr/bin/python3 scripts/plot_pair.py RUN_DIR [RUN_DIR ...] [-o PNG] [--title TEXT]
Runs of scenarios/capsule_pair.toml or capsule_pair_quick.toml (or any run with two membranes in a shear flow
between z walls moving along x). From diagnostics.csv the centroid columns m0_cx, m0_cz, m1_cx, m1_cz; the offsets
dx, dz are those of the upper capsule (the membrane with the larger initial cz) from the lower one, in units of the
radius a of membrane[0] (membrane[0].radius in config.resolved.toml; the mean distance of its nodes from its centre
for a membrane read from a file is not known here, so a generated shape is required). From config.resolved.toml: the
shear rate k = (boundary.z_upper_velocity[0] - boundary.z_lower_velocity[0]) / domain.Lz and, for neo-Hookean
capsules, the capillary number G = mu k a / E_s. Left panel: dz/a against dx/a (the relative trajectory; a circle at
the start, a square at the end); right panel: dz/a against k t. Prints each run's initial, largest and final dz/a
and the range of dx/a. Default PNG: pair.png in the first RUN_DIR.
"""
import argparse
import os

import matplotlib.pyplot as plt
import numpy as np

import plot_common as pc


def read_run(run_dir):
    cfg = pc.read_config(run_dir)
    k = pc.shear_rate(cfg)
    if k == 0.0:
        pc.fail(f"{run_dir}: the z walls do not move (k = 0): not a shear run")
    membranes = cfg.get("membrane", [])
    if len(membranes) != 2:
        pc.fail(f"{run_dir}: {len(membranes)} membranes, expected two")
    m0 = membranes[0]
    if "radius" not in m0 or m0.get("shape") not in ("sphere",):
        pc.fail(f"{run_dir}: membrane[0] is not a generated sphere: its radius a is not known")
    a = m0["radius"]
    diag = pc.read_diagnostics(run_dir)
    cx = [pc.membrane_column(diag, "cx", m) for m in (0, 1)]
    cz = [pc.membrane_column(diag, "cz", m) for m in (0, 1)]
    upper, lower = (1, 0) if cz[1][0] >= cz[0][0] else (0, 1)
    label = os.path.basename(os.path.normpath(run_dir))
    if m0.get("law") == "neo_hookean":
        G = cfg["fluid"]["mu"] * k * a / m0["Es"]
        label = f"G = {G:.3g}, {pc.resolution_of(cfg, 0)}"
    return {"dir": run_dir, "k": k, "a": a, "label": label, "kt": k * diag["time"],
            "dx": (cx[upper] - cx[lower]) / a, "dz": (cz[upper] - cz[lower]) / a}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run_dirs", nargs="+", metavar="RUN_DIR")
    parser.add_argument("-o", "--output", help="PNG to write (default pair.png in the first RUN_DIR)")
    parser.add_argument("--title", default="Two capsules crossing in simple shear", help="figure title")
    args = parser.parse_args()

    runs = [read_run(d) for d in args.run_dirs]
    fig, (ax_traj, ax_time) = plt.subplots(1, 2, figsize=(12.0, 4.4))
    for i, r in enumerate(runs):
        color = f"C{i}"
        ax_traj.plot(r["dx"], r["dz"], "-", color=color, lw=1.5, label=r["label"])
        ax_traj.plot(r["dx"][0], r["dz"][0], "o", color=color, ms=6)
        ax_traj.plot(r["dx"][-1], r["dz"][-1], "s", color=color, ms=6)
        ax_time.plot(r["kt"], r["dz"], "-", color=color, lw=1.5, label=r["label"])
        ax_time.axhline(r["dz"][0], color=color, ls=":", lw=1)
        print(f"{r['dir']}: {r['label']}, k = {r['k']:g} 1/s, a = {r['a']:g} m, k t = 0 ... {r['kt'][-1]:.3g}: "
              f"initial dz/a = {r['dz'][0]:.4f}, largest {r['dz'].max():.4f} (at dx/a = "
              f"{r['dx'][np.argmax(r['dz'])]:.3f}), final {r['dz'][-1]:.4f} (change {r['dz'][-1] - r['dz'][0]:+.4f}); "
              f"dx/a from {r['dx'][0]:.3f} to {r['dx'][-1]:.3f}")
    ax_traj.axvline(0, color="0.6", lw=0.8)
    ax_traj.plot([], [], "ko", ms=5, label="start")
    ax_traj.plot([], [], "ks", ms=5, label="end")
    ax_traj.set_xlabel("$\\Delta x / a$ (flow direction)")
    ax_traj.set_ylabel("$\\Delta z / a$ (gradient direction)")
    ax_traj.set_title("Relative trajectory of the centroids", fontsize=10)
    ax_traj.set_ylim(bottom=0)
    ax_traj.grid(alpha=0.3)
    ax_traj.legend(fontsize="small", loc="lower center")
    ax_time.plot([], [], "k:", lw=1, label="initial $\\Delta z / a$")
    ax_time.set_xlabel("dimensionless time k t")
    ax_time.set_ylabel("$\\Delta z / a$")
    ax_time.set_xlim(left=0)
    ax_time.set_ylim(bottom=0)
    ax_time.set_title("Gradient-direction separation", fontsize=10)
    ax_time.grid(alpha=0.3)
    ax_time.legend(fontsize="small", loc="lower right")
    fig.suptitle(args.title, fontsize=11)
    fig.tight_layout()
    out = args.output or os.path.join(args.run_dirs[0], "pair.png")
    fig.savefig(out, dpi=pc.DPI)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
