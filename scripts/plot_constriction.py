#!/usr/bin/python3
"""A capsule through a constriction: its extents against its position (Park & Dimitrakopoulos 2013, Soft Matter 9:8844).

Usage: /usr/bin/python3 scripts/plot_constriction.py RUN_DIR [RUN_DIR ...] [-o PNG]
Runs of scenarios/capsule_constriction.toml or capsule_constriction_quick.toml. From diagnostics.csv the columns
length_x, length_y, length_z (the capsule's extents), throat_position (its centroid from the throat's centre along the
channel) and in_throat; from config.resolved.toml the capsule's radius a (membrane[0].radius, a generated sphere), the
throat's half-height H_c (half the least of wall[0].throat across the axis) and the channel's mean velocity
U = Q / (channel cross-section). Plots l_x/2a, l_y/2a, l_z/2a against x_c/H_c, Park & Dimitrakopoulos' axes. Prints
for each run the time the centroid spent in the throat (in a/U), the largest l_x/2a and the least l_y/2a, and where
the run ended. Default PNG: constriction.png in the first RUN_DIR.
"""
import argparse
import os

import matplotlib.pyplot as plt
import numpy as np

import plot_common as pc


def read_run(run_dir):
    cfg = pc.read_config(run_dir)
    walls, membranes = cfg.get("wall", []), cfg.get("membrane", [])
    if not walls or walls[0].get("shape") != "constriction":
        pc.fail(f"{run_dir}: wall[0] is not a constriction")
    if not membranes or membranes[0].get("shape") != "sphere":
        pc.fail(f"{run_dir}: membrane[0] is not a generated sphere: its radius a is not known")
    a = membranes[0]["radius"]
    axis = int(np.argmax(np.abs(walls[0]["axis"])))
    across = [d for d in range(3) if d != axis]
    half_throat = 0.5 * min(walls[0]["throat"][d] for d in across)
    section = walls[0]["size"][across[0]] * walls[0]["size"][across[1]]
    U = cfg["fluid"]["flow_rate"][axis] / section
    diag = pc.read_diagnostics(run_dir)
    t = diag["time"]
    inside = diag["in_throat"] > 0.5
    dt = np.diff(t, prepend=t[0])
    return {"label": os.path.basename(os.path.normpath(run_dir)), "x": diag["throat_position"] / half_throat,
            "lx": diag["length_x"] / (2 * a), "ly": diag["length_y"] / (2 * a), "lz": diag["length_z"] / (2 * a),
            "inside": float(np.sum(dt[inside])) * U / a, "end": t[-1] * U / a, "entered": bool(inside.any()),
            "left": bool(inside.any() and not inside[-1])}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run_dirs", nargs="+", metavar="RUN_DIR")
    parser.add_argument("-o", "--output", help="PNG to write (default constriction.png in the first RUN_DIR)")
    args = parser.parse_args()
    runs = [read_run(d) for d in args.run_dirs]
    fig, ax = plt.subplots(figsize=(7.0, 4.4))
    for i, r in enumerate(runs):
        for key, style, name in (("lx", "-", "l_x"), ("ly", "--", "l_y"), ("lz", ":", "l_z")):
            ax.plot(r["x"], r[key], style, color=f"C{i}", lw=1.5, label=f"{name}/2a, {r['label']}")
        state = "passed the throat" if r["left"] else ("in the throat" if r["entered"] else "before the throat")
        print(f"{r['label']}: in the throat for {r['inside']:.3f} a/U; largest l_x/2a {r['lx'].max():.4f}, least "
              f"l_y/2a {r['ly'].min():.4f}; ended at t = {r['end']:.3f} a/U, x_c/H_c = {r['x'][-1]:.3f} ({state})")
    ax.axvspan(-1, 1, color="0.9", label="throat")
    ax.set_xlabel("x_c / H_c (centroid from the throat's centre)")
    ax.set_ylabel("extent / 2a")
    ax.set_title("Capsule through a constriction (Park & Dimitrakopoulos' case)")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    out = args.output or os.path.join(args.run_dirs[0], "constriction.png")
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
