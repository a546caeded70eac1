#!/usr/bin/python3
"""Figs. 3 and 6 of the paper: pictures of the membrane at chosen frames, rendered from fields_NNNNNN.h5.

Usage: /usr/bin/python3 scripts/plot_shapes.py RUN_DIR [--frames i,j,k] [-o PNG] [--membrane I] [--view ELEV,AZIM]
Each 6-node triangle (vertices 0, 1, 2, then mid-sides 01, 12, 20) is drawn as its four linear sub-triangles with
matplotlib's plot_trisurf, on equal axes shared by every panel, titled with the frame's time. Default frames:
four spread evenly over the run. Default PNG: RUN_DIR/shapes.png.
"""
import argparse
import os

import h5py
import matplotlib.pyplot as plt
import numpy as np

import plot_common as pc

# Sub-triangles of a 6-node triangle in terms of its local nodes 0, 1, 2 (vertices), 3 = 01, 4 = 12, 5 = 20.
SUB_TRIANGLES = np.array([[0, 3, 5], [3, 1, 4], [5, 4, 2], [3, 4, 5]])


def read_frame(path, membrane):
    """(time, nodes [N,3], linear triangles [4T,3]) of one membrane in one frame."""
    with h5py.File(path, "r") as f:
        group = f"membranes/membrane{membrane}"
        if group not in f:
            pc.fail(f"{path} has no {group}")
        nodes = f[group]["nodes"][()]
        conn = f[group]["connectivity"][()]
        time = float(f.attrs["time"])
    if conn.ndim != 2 or conn.shape[1] != 6:
        pc.fail(f"{path}: connectivity has shape {conn.shape}, expected [T, 6] (6-node triangles)")
    return time, nodes, conn[:, SUB_TRIANGLES].reshape(-1, 3)


def parse_frames(text, count):
    """Frame indices from 'i,j,k' (negative counts from the end), or four spread evenly."""
    if text is None:
        return sorted(set(np.linspace(0, count - 1, min(4, count)).round().astype(int).tolist()))
    try:
        frames = [int(s) for s in text.split(",")]
    except ValueError:
        pc.fail(f"--frames {text!r}: expected comma-separated integers such as 0,3,9")
    for i in frames:
        if not -count <= i < count:
            pc.fail(f"--frames: frame {i} does not exist (the run has frames 0 ... {count - 1})")
    return [i % count for i in frames]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run_dir")
    parser.add_argument("--frames", help="comma-separated frame indices, e.g. 0,3,9 (default: four, evenly spread)")
    parser.add_argument("-o", "--output", help="PNG to write (default RUN_DIR/shapes.png)")
    parser.add_argument("--membrane", type=int, default=0, help="membrane index (default 0)")
    parser.add_argument("--view", default="15,-75", help="camera elevation,azimuth in degrees (default 15,-75)")
    args = parser.parse_args()

    cfg = pc.read_config(args.run_dir)
    files = pc.frame_files(args.run_dir)
    frames = parse_frames(args.frames, len(files))
    try:
        elev, azim = (float(s) for s in args.view.split(","))
    except ValueError:
        pc.fail(f"--view {args.view!r}: expected ELEV,AZIM in degrees, e.g. 20,-60")

    # SI runs of micrometre-sized capsules are drawn in um; the paper's nondimensional runs as they are.
    micro = cfg["domain"]["Lx"] < 1e-2
    scale, unit = (1e6, " ($\\mu$m)") if micro else (1.0, " / L")
    data = []
    for i in frames:
        time, nodes, tris = read_frame(files[i], args.membrane)
        data.append((i, time, nodes * scale, tris))
    everything = np.vstack([d[2] for d in data])
    centre = 0.5 * (everything.min(axis=0) + everything.max(axis=0))
    half = 0.5 * (everything.max(axis=0) - everything.min(axis=0)).max() * 1.05

    kind = cfg.get("scenario", {}).get("kind", "none")
    shear = kind in ("capsule_shear", "oblate_shear", "bending_shear")
    k = pc.shear_rate(cfg) if shear else 0.0
    fig = plt.figure(figsize=(3.0 * len(data), 3.4))
    for n, (i, time, nodes, tris) in enumerate(data):
        ax = fig.add_subplot(1, len(data), n + 1, projection="3d")
        ax.plot_trisurf(nodes[:, 0], nodes[:, 1], nodes[:, 2], triangles=tris, color="tab:red",
                        edgecolor=(0, 0, 0, 0.25), linewidth=0.2, shade=True)
        ax.set_xlim(centre[0] - half, centre[0] + half)
        ax.set_ylim(centre[1] - half, centre[1] + half)
        ax.set_zlim(centre[2] - half, centre[2] + half)
        ax.set_box_aspect((1, 1, 1))
        ax.view_init(elev=elev, azim=azim)
        ax.set_xlabel("x" + unit, fontsize=8, labelpad=-2)
        ax.set_ylabel("y" + unit, fontsize=8, labelpad=-2)
        ax.set_zlabel("z" + unit, fontsize=8, labelpad=-2)
        ax.tick_params(labelsize=6, pad=0)
        ax.locator_params(nbins=4)
        title = f"k t = {k * time:.3g}" if shear else f"t = {time:.4g}"
        ax.set_title(f"{title} (frame {i})", fontsize=9)
    fig.suptitle(f"Membrane, {pc.label_of(cfg, args.run_dir)}", fontsize=10)
    fig.subplots_adjust(left=0.01, right=0.97, bottom=0.03, top=0.86, wspace=0.12)
    out = args.output or os.path.join(args.run_dir, "shapes.png")
    fig.savefig(out, dpi=pc.DPI)
    print(f"{out}: frames {frames} at times {[round(d[1], 6) for d in data]}")


if __name__ == "__main__":
    main()
