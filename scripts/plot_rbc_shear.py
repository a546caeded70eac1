#!/usr/bin/python3
"""A red blood cell in simple shear: tumbling or tank-treading/swinging, from the orientation of its symmetry axis.

Usage: /usr/bin/python3 scripts/plot_rbc_shear.py RUN_DIR [RUN_DIR ...] [-o PNG] [--title TEXT] [--membrane M]
Runs of scenarios/rbc_shear.toml or rbc_shear_quick.toml (or any run with a disc-like membrane in the shear flow
u = (k z, 0, 0) between z walls moving along x), read from the frames fields_NNNNNN.h5. In each frame:
  - the symmetry axis n of the cell: the principal axis of the membrane surface with the largest moment of inertia
    (the smallest eigenvalue of the area-weighted second moment S = int (x - c)(x - c)^T dA, c the centroid);
  - phi, the angle of n in the shear plane x-z from +z towards +x (the sense in which the flow turns a material line),
    made continuous in time: a tumbling disc advances phi by pi per flip, a swinging one oscillates about a mean
    (-phi is the inclination of the disc's plane from the flow direction);
  - psi, the angle in the same plane around the centroid of one material node (the node nearest the rim on the +x
    side at the first frame), made continuous: psi - phi grows by 2 pi per turn of the membrane around the cell when
    it tank-treads, and only oscillates when the cell tumbles (the node stays in place on the cell).
Prints, per run: the number of flips (whole half-turns of phi), the k t at which the axis passes the flow direction,
the mean and range of phi over the second half of the run, and the tank-treading frequency
f_tt / k = (change of psi - phi over the second half) / (2 pi k t).
Left panel: phi / pi against k t; right panel: (psi - phi) / (2 pi), the membrane's turns around the cell. With
--shapes KT1,KT2,...: below, one row per run, the cell seen along y (nodes projected on x-z, in micrometres around
its centroid) at the frames nearest those k t, with its symmetry axis (black) and the tracked node (red).
Default PNG: rbc_shear.png in the first RUN_DIR.
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
        if "membranes" not in f:
            pc.fail(f"{path} has no membranes")
        g = f["membranes"]
        offsets, ids = g["node_offsets"][()], g["membrane_id"][()]
        if not 0 <= membrane < len(offsets) - 1:
            pc.fail(f"--membrane {membrane}: {path} has {len(offsets) - 1} membrane(s)")
        nodes = g["nodes"][()][offsets[membrane]:offsets[membrane + 1]]
        conn = g["connectivity"][()][ids == membrane] - offsets[membrane]
        return float(f.attrs["time"]), nodes, conn[:, SUB_TRIANGLES].reshape(-1, 3)


def surface_moments(nodes, tris):
    """(area-weighted centroid c, second moment S = int (x - c)(x - c)^T dA) of a triangulated surface (exact for
    flat triangles)."""
    v = nodes[tris]  # [T, 3 vertices, 3]
    area = 0.5 * np.linalg.norm(np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]), axis=1)
    total = area.sum()
    c = (area[:, None] * v.mean(axis=1)).sum(axis=0) / total
    w = v - c
    s = w.sum(axis=1)
    # int over a flat triangle of x x^T dA = A/12 (sum_i v_i v_i^T + (sum_i v_i)(sum_i v_i)^T)
    second = np.einsum("t,tij,tik->jk", area, w, w) + np.einsum("t,tj,tk->jk", area, s, s)
    return c, second / 12.0


def symmetry_axis(nodes, tris):
    """(centroid, unit symmetry axis): the eigenvector of the smallest eigenvalue of S (largest moment of inertia)."""
    c, second = surface_moments(nodes, tris)
    values, vectors = np.linalg.eigh(second)
    return c, vectors[:, 0]


def rim_node(nodes, c):
    """The node farthest out on the +x side, near the plane y = c_y through the centroid c."""
    r = nodes - c
    return int(np.argmax(r[:, 0] - np.abs(r[:, 1]) - np.abs(r[:, 2])))


def orientation(frames):
    """(phi, psi) arrays over frames [(nodes, tris), ...]: continuous angles in the x-z plane, from +z towards +x,
    of the symmetry axis and of the material node nearest the rim on the +x side at the first frame."""
    phi, psi = [], []
    previous = None
    tracked = None
    for nodes, tris in frames:
        c, n = symmetry_axis(nodes, tris)
        if previous is None:
            if n[2] < 0 or (n[2] == 0 and n[0] < 0):
                n = -n
        elif np.dot(n, previous) < 0:
            n = -n  # the axis is a director: keep the sign continuous between frames
        previous = n
        phi.append(np.arctan2(n[0], n[2]))
        if tracked is None:
            tracked = rim_node(nodes, c)
        r = nodes[tracked] - c
        psi.append(np.arctan2(r[0], r[2]))
    return np.unwrap(np.array(phi)), np.unwrap(np.array(psi))


def summary(kt, phi, psi):
    """The key figures of one run: flips, phi over the second half, tank-treading frequency f_tt / k."""
    half = kt >= 0.5 * kt[-1]
    rel = psi - phi
    span = kt[half][-1] - kt[half][0]
    turns = (rel[half][-1] - rel[half][0]) / (2 * np.pi)
    # k t at which the axis passes the flow direction (phi = pi/2 + n pi), between frames by linear interpolation
    crossings = []
    level = (phi - np.pi / 2) / np.pi
    for i in np.nonzero(np.floor(level[1:]) != np.floor(level[:-1]))[0]:
        target = np.ceil(min(level[i], level[i + 1]))
        crossings.append(kt[i] + (target - level[i]) / (level[i + 1] - level[i]) * (kt[i + 1] - kt[i]))
    return {"flips": int(np.floor(abs(phi[-1] - phi[0]) / np.pi + 1e-9)), "crossings": crossings,
            "phi_mean": float(phi[half].mean()), "phi_min": float(phi[half].min()),
            "phi_max": float(phi[half].max()),
            "f_tt": float(turns / span) if span > 0 else 0.0,
            "rel_range": float(rel[half].max() - rel[half].min())}


def read_run(run_dir, membrane):
    cfg = pc.read_config(run_dir)
    k = pc.shear_rate(cfg)
    if k == 0.0:
        pc.fail(f"{run_dir}: the z walls do not move (k = 0): not a shear run")
    times, frames = [], []
    for path in pc.frame_files(run_dir):
        t, nodes, tris = read_frame(path, membrane)
        times.append(t)
        frames.append((nodes, tris))
    if len(frames) < 3:
        pc.fail(f"{run_dir}: {len(frames)} frame(s); at least three are needed")
    phi, psi = orientation(frames)
    m = cfg["membrane"][membrane]
    lam = m.get("viscosity_ratio", 1.0)
    label = f"$\\lambda$ = {lam:g}"
    if m.get("law") == "skalak" and "R0" in m:
        # G_s = C11 / 2 and C = C21 / (2 G_s) (src/immerse/membrane/Skalak.hpp)
        label += f", Ca = {cfg['fluid']['mu'] * k * m['R0'] / (m['C11'] / 2):.2g}, C = {m['C21'] / m['C11']:.3g}"
    label += f" ({pc.resolution_of(cfg, membrane)})"
    return {"dir": run_dir, "k": k, "lambda": lam, "label": label, "kt": k * np.array(times), "phi": phi,
            "psi": psi, "frames": frames}


def draw_shape(ax, run, frame, color):
    """The cell of one frame seen along y (nodes projected on x-z, centred), its symmetry axis and the tracked node."""
    nodes, tris = run["frames"][frame]
    c, _ = symmetry_axis(nodes, tris)
    r = (nodes - c) * 1e6
    ax.plot(r[:, 0], r[:, 2], ".", color=color, ms=1, alpha=0.3)
    first, first_tris = run["frames"][0]
    c0, _ = symmetry_axis(first, first_tris)
    node = rim_node(first, c0)
    size = 1.1e6 * max(np.linalg.norm(x - x.mean(axis=0), axis=1).max() for x, _ in run["frames"])
    phi = run["phi"][frame]
    ax.plot([-size * np.sin(phi), size * np.sin(phi)], [-size * np.cos(phi), size * np.cos(phi)], "k-", lw=0.8)
    ax.plot(r[node, 0], r[node, 2], "o", color="red", ms=4, zorder=3)
    ax.set_aspect("equal")
    ax.set_xlim(-size, size)
    ax.set_ylim(-size, size)
    ax.set_xticks([])
    ax.set_yticks([])
    ax.set_title(f"k t = {run['kt'][frame]:.1f}, $\\lambda$ = {run['lambda']:g}", fontsize=8)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run_dirs", nargs="+", metavar="RUN_DIR")
    parser.add_argument("-o", "--output", help="PNG to write (default rbc_shear.png in the first RUN_DIR)")
    parser.add_argument("--title", default="A red blood cell in simple shear", help="figure title")
    parser.add_argument("--membrane", type=int, default=0, help="membrane index (default 0)")
    parser.add_argument("--shapes", metavar="KT1,KT2,...",
                        help="also draw each run's cell seen along y at the frames nearest these k t (one row per run)")
    args = parser.parse_args()

    runs = [read_run(d, args.membrane) for d in args.run_dirs]
    times = pc.parse_numbers("--shapes", args.shapes) if args.shapes else []
    rows = len(runs) if times else 0
    fig = plt.figure(figsize=(12.0, 4.4 + 1.6 * rows))
    grid = fig.add_gridspec(1 + rows, 2 * max(len(times), 1), height_ratios=[4.4] + [1.6] * rows)
    half = max(len(times), 1)
    ax_phi, ax_tt = fig.add_subplot(grid[0, :half]), fig.add_subplot(grid[0, half:])
    for i, r in enumerate(runs):
        s = summary(r["kt"], r["phi"], r["psi"])
        motion = "tumbling" if s["flips"] >= 1 else "swinging/tank-treading"
        text = r["label"].replace("$\\lambda$", "lambda")
        print(f"{r['dir']}: {text}, k t = 0 ... {r['kt'][-1]:.3g}, {len(r['kt'])} frames: {motion}; "
              f"flips {s['flips']} (phi from {r['phi'][0]:.3f} to {r['phi'][-1]:.3f} rad); second half: "
              f"phi mean {s['phi_mean']:.3f} rad, range {s['phi_min']:.3f} ... {s['phi_max']:.3f} rad; "
              f"tank-treading f_tt / k = {s['f_tt']:.4f} (psi - phi spans {s['rel_range']:.3f} rad)")
        if s["crossings"]:
            c = s["crossings"]
            gaps = f", k t between flips {np.mean(np.diff(c)):.2f}" if len(c) > 1 else ""
            print(f"  the axis passes the flow direction at k t = {', '.join(f'{x:.2f}' for x in c)}{gaps}")
        color = f"C{i}"
        ax_phi.plot(r["kt"], r["phi"] / np.pi, "-", color=color, lw=1.5, label=r["label"])
        ax_tt.plot(r["kt"], (r["psi"] - r["phi"]) / (2 * np.pi), "-", color=color, lw=1.5, label=r["label"])
    ax_phi.set_xlabel("dimensionless time k t")
    ax_phi.set_ylabel("$\\varphi / \\pi$ (symmetry axis from z towards x)")
    ax_phi.set_title("Orientation of the cell: +1 per flip", fontsize=10)
    ax_phi.grid(alpha=0.3)
    ax_phi.legend(fontsize="small", loc="upper left")
    ax_tt.set_xlabel("dimensionless time k t")
    ax_tt.set_ylabel("$(\\psi - \\varphi) / 2\\pi$")
    ax_tt.set_title("Turns of a membrane node around the cell (tank-treading)", fontsize=10)
    ax_tt.grid(alpha=0.3)
    ax_tt.legend(fontsize="small", loc="upper left")
    for i, r in enumerate(runs[:rows]):
        for j, t in enumerate(times):
            ax = fig.add_subplot(grid[1 + i, 2 * j:2 * j + 2])
            draw_shape(ax, r, int(np.argmin(np.abs(r["kt"] - t))), f"C{i}")
    fig.suptitle(args.title, fontsize=11)
    fig.tight_layout()
    out = args.output or os.path.join(args.run_dirs[0], "rbc_shear.png")
    fig.savefig(out, dpi=pc.DPI)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
