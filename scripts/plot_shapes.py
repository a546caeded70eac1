#!/usr/bin/python3
"""Figs. 3, 6, 14 and 15 of the paper: pictures of the membranes at chosen frames, rendered from fields_NNNNNN.h5.

Usage: /usr/bin/python3 scripts/plot_shapes.py RUN_DIR [--frames i,j,k | --times t1,t2 | --forces F1,F2]
           [-o PNG] [--membrane I] [--view ELEV,AZIM | --side x|y|z] [--box] [--columns N] [--panel W,H]
           [--title TEXT]
Every membrane of a frame is drawn (one colour each when there are several; --membrane I draws only membrane I).
Each 6-node triangle (vertices 0, 1, 2, then mid-sides 01, 12, 20) is drawn as its four linear sub-triangles, all
membranes of a panel in one depth-sorted collection shaded by the angle to the light, in orthographic projection on
equal axes. Which frames:
  --frames i,j,k   frame indices (negative counts from the end); default four spread evenly over the run;
  --times t1,t2    the frame nearest to each simulated time (s; the run's own time unit for nondimensional runs);
  --forces F1,F2   rbc_stretch runs (Fig. 14): the cell at the steady state of each force (pN) of its stretch.csv.
                   The steady step is found in diagnostics.csv (its diameters equal the stretch.csv row); the frame
                   written at that step is drawn, so run the sweep with --set output.fields_every=1 (with
                   --set output.fluid_fields=false to keep the frames small); with a coarser schedule the last
                   frame under that force is drawn and its diameters are printed beside the steady ones.
--box draws the outline of the computational box and uses it as the axes' extent (Fig. 15: the cells in the
channel); membranes that left the box through a periodic side are shifted back by whole periods (by their
centroid); a --side panel is clipped to the box and draws the parts beyond a periodic side again at the opposite
side. Default view: a 3-D panel seen from --view 15,-75 (elevation, azimuth in degrees; 0,-90 looks along +y with
x to the right). --side x|y|z instead draws a flat, exactly scaled 2-D panel seen along that axis (x: y to the
right and z up; y: x to the right, z up; z: x to the right, y up), faces painted far to near.
Default PNG: RUN_DIR/shapes.png.
"""
import argparse
import os

import h5py
import matplotlib
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.collections import PolyCollection
from mpl_toolkits.mplot3d.art3d import Poly3DCollection

import plot_common as pc

# Sub-triangles of a 6-node triangle in terms of its local nodes 0, 1, 2 (vertices), 3 = 01, 4 = 12, 5 = 20.
SUB_TRIANGLES = np.array([[0, 3, 5], [3, 1, 4], [5, 4, 2], [3, 4, 5]])
AXES = ("x", "y", "z")
# --side: (horizontal axis, vertical axis, +1 if the camera sits on the + side of the depth axis, else -1).
SIDES = {"x": (1, 2, 1), "y": (0, 2, -1), "z": (0, 1, 1)}


def frame_time(path):
    with h5py.File(path, "r") as f:
        return float(f.attrs["time"])


def read_membranes(path, only):
    """(time, [(index, nodes [N,3], linear triangles [4T,3]), ...]) of the membranes in one frame.

    /membranes holds all membranes in one surface: membrane k owns nodes node_offsets[k] .. node_offsets[k+1]-1
    and the elements whose membrane_id is k."""
    with h5py.File(path, "r") as f:
        time = float(f.attrs["time"])
        if "membranes" not in f or "node_offsets" not in f["membranes"]:
            pc.fail(f"{path} has no membranes")
        g = f["membranes"]
        offsets, ids = g["node_offsets"][()], g["membrane_id"][()]
        nodes_all, conn_all = g["nodes"][()], g["connectivity"][()]
        count = len(offsets) - 1
        if only is not None and not 0 <= only < count:
            pc.fail(f"--membrane {only}: {path} has membranes 0 ... {count - 1}")
        if conn_all.ndim != 2 or conn_all.shape[1] != 6:
            pc.fail(f"{path}: connectivity has shape {conn_all.shape}, expected [T, 6] (6-node triangles)")
        out = []
        for m in range(count):
            if only is not None and m != only:
                continue
            nodes = nodes_all[offsets[m]:offsets[m + 1]]
            conn = conn_all[ids == m] - offsets[m]
            out.append((m, nodes, conn[:, SUB_TRIANGLES].reshape(-1, 3)))
    return time, out


def frames_by_index(text, count):
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


def frames_by_time(text, times):
    """The frame nearest to each time of 't1,t2'."""
    wanted = pc.parse_numbers("--times", text)
    for t in wanted:
        if not times[0] - 1e-9 * abs(times[-1]) <= t <= times[-1] * (1 + 1e-9):
            pc.fail(f"--times: {t:g} is outside the frames' times {times[0]:g} ... {times[-1]:g}")
    return [int(np.argmin(np.abs(times - t))) for t in wanted]


def frames_by_force(text, run_dir, times, files):
    """rbc_stretch: for each force of 'F1,F2' (pN) the frame of its steady state; also the panel labels."""
    force, axial, transverse = pc.read_stretch(run_dir)
    diag = pc.read_diagnostics(run_dir)
    for col in ("axial_um", "transverse_um"):
        if col not in diag:
            pc.fail(f"{run_dir}/diagnostics.csv has no column {col!r}: not an rbc_stretch run")
    # The steady step of force i: the first row after that of force i-1 whose diameters equal stretch.csv's
    # (both are written from the same positions at full precision); of a run of equal rows (a cell at rest under
    # zero force), the last.
    ends, start = [], 0
    for a, t in zip(axial, transverse):
        same = (diag["axial_um"] == a) & (diag["transverse_um"] == t)
        hits = np.nonzero(same[start:])[0]
        if hits.size == 0:
            pc.fail(f"{run_dir}: no row of diagnostics.csv has the steady diameters {a:g}, {t:g} um of stretch.csv "
                    f"(diagnostics_every > 1?)")
        start += int(hits[0])
        while start + 1 < same.size and same[start + 1]:
            start += 1
        ends.append(diag["time"][start])
        start += 1
    frames, labels = [], []
    for F in pc.parse_numbers("--forces", text):
        match = np.nonzero(np.isclose(force, F, rtol=1e-6, atol=1e-9))[0]
        if match.size == 0:
            listed = ", ".join(f"{x:g}" for x in force)
            pc.fail(f"--forces: {F:g} pN is not a force of {run_dir}/stretch.csv ({listed})")
        i = int(match[0])
        t_end, t_begin = ends[i], (ends[i - 1] if i > 0 else -np.inf)
        under = np.nonzero((times > t_begin + 1e-12 * abs(t_end)) & (times <= t_end * (1 + 1e-12)))[0]
        if under.size == 0:
            pc.fail(f"--forces: no frame was written while {F:g} pN was applied (t in ({t_begin:g}, {t_end:g}] s); "
                    f"rerun with --set output.fields_every=1")
        j = int(under[-1])
        if abs(times[j] - t_end) > 1e-12 * abs(t_end):
            _, membranes = read_membranes(files[j], 0)
            nodes = membranes[0][1]
            d = np.ptp(nodes[:, :2], axis=0) * 1e6
            print(f"warning: {F:g} pN: no frame at the steady step (t = {t_end:g} s); drawing frame {j} "
                  f"(t = {times[j]:g} s, diameters {d[0]:.3f}/{d[1]:.3f} um, steady {axial[i]:.3f}/"
                  f"{transverse[i]:.3f} um)")
        frames.append(j)
        labels.append(f"F = {F:g} pN")
    return frames, labels


def box_of(cfg):
    """(lower corner, upper corner, periodic flags) of the computational box."""
    lo = np.asarray(cfg["domain"].get("origin", [0.0, 0.0, 0.0]), dtype=float)
    size = np.array([cfg["domain"][f"L{a}"] for a in AXES], dtype=float)
    periodic = np.array([cfg["boundary"][a] == "periodic" for a in AXES])
    return lo, lo + size, periodic


def into_box(nodes, lo, hi, periodic):
    """Shifts a membrane by whole periods along periodic axes so that its centroid lies in the box."""
    size = hi - lo
    shift = np.where(periodic, np.floor((nodes.mean(axis=0) - lo) / size) * size, 0.0)
    return nodes - shift


def periodic_copies(nodes, lo, hi, periodic):
    """The membrane and, where it sticks out through a periodic side, its images one period over."""
    copies = [nodes]
    for d in np.nonzero(periodic)[0]:
        shift = np.zeros(3)
        shift[d] = hi[d] - lo[d]
        extra = []
        for x in copies:
            if x[:, d].min() < lo[d]:
                extra.append(x + shift)
            if x[:, d].max() > hi[d]:
                extra.append(x - shift)
        copies += extra
    return copies


def draw_box(ax, lo, hi):
    """The 12 edges of the box."""
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    for i in range(8):
        for j in range(i + 1, 8):
            if np.count_nonzero(corners[i] != corners[j]) == 1:
                ax.plot(*zip(corners[i], corners[j]), color="k", lw=0.8)


def shaded_colors(tris_xyz, base, light):
    """Face colours: the base colour scaled by |cos| of the angle between the face normal and the light."""
    n = np.cross(tris_xyz[:, 1] - tris_xyz[:, 0], tris_xyz[:, 2] - tris_xyz[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
    intensity = 0.35 + 0.65 * np.abs(n @ light)
    rgb = np.asarray(matplotlib.colors.to_rgb(base))
    return np.clip(intensity[:, None] * rgb[None, :], 0, 1)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run_dir")
    pick = parser.add_mutually_exclusive_group()
    pick.add_argument("--frames", help="comma-separated frame indices, e.g. 0,3,9 (default: four, evenly spread)")
    pick.add_argument("--times", help="comma-separated simulated times: the nearest frame to each")
    pick.add_argument("--forces", help="rbc_stretch: comma-separated forces (pN) of stretch.csv: the steady frames")
    parser.add_argument("-o", "--output", help="PNG to write (default RUN_DIR/shapes.png)")
    parser.add_argument("--membrane", type=int, help="draw only this membrane (default: all)")
    view = parser.add_mutually_exclusive_group()
    view.add_argument("--view", default="15,-75", help="3-D camera elevation,azimuth in degrees (default 15,-75)")
    view.add_argument("--side", choices=AXES, help="flat 2-D view along this axis instead of a 3-D panel")
    parser.add_argument("--box", action="store_true", help="draw the computational box and fit the axes to it")
    parser.add_argument("--columns", type=int, help="panels per row (default: all panels in one row)")
    parser.add_argument("--panel", help="size of one panel W,H in inches (default 3.0,3.4; --side: from the extent)")
    parser.add_argument("--title", help="figure title (default: from the scenario)")
    args = parser.parse_args()

    cfg = pc.read_config(args.run_dir)
    files = pc.frame_files(args.run_dir)
    kind = pc.scenario_kind(cfg)
    labels = None
    if args.times is not None or args.forces is not None:
        times = np.array([frame_time(p) for p in files])
        if args.times is not None:
            frames = frames_by_time(args.times, times)
        else:
            if kind != "rbc_stretch":
                pc.fail(f"--forces: {args.run_dir} is a {kind!r} run, not rbc_stretch")
            frames, labels = frames_by_force(args.forces, args.run_dir, times, files)
    else:
        frames = frames_by_index(args.frames, len(files))
    try:
        elev, azim = (float(s) for s in args.view.split(","))
        panel = None
        if args.panel is not None:
            panel_w, panel_h = (float(s) for s in args.panel.split(","))
            panel = (panel_w, panel_h)
    except ValueError:
        pc.fail(f"--view {args.view!r} / --panel {args.panel!r}: expected two comma-separated numbers each")
    if args.columns is not None and args.columns < 1:
        pc.fail(f"--columns {args.columns}: expected a positive integer")

    # SI runs of micrometre-sized capsules are drawn in um; the paper's nondimensional runs as they are.
    micro = cfg["domain"]["Lx"] < 1e-2
    scale, unit = (1e6, " ($\\mu$m)") if micro else (1.0, " / L")
    lo, hi, periodic = box_of(cfg)
    data = []
    for i in frames:
        time, membranes = read_membranes(files[i], args.membrane)
        if args.box:
            membranes = [(m, into_box(x, lo, hi, periodic), t) for m, x, t in membranes]
            if args.side is not None:  # a 2-D panel is clipped to the box: draw the images across periodic sides
                membranes = [(m, c, t) for m, x, t in membranes for c in periodic_copies(x, lo, hi, periodic)]
        data.append((i, time, [(m, x * scale, t) for m, x, t in membranes]))
    if args.box:
        lower, upper = lo * scale, hi * scale
    else:
        # The bounding box of every drawn node, padded; the panels keep equal scales along x, y and z.
        everything = np.vstack([x for _, _, ms in data for _, x, _ in ms])
        pad = 0.04 * (everything.max(axis=0) - everything.min(axis=0)).max()
        lower, upper = everything.min(axis=0) - pad, everything.max(axis=0) + pad

    shear = kind in pc.SHEAR_KINDS
    k = pc.shear_rate(cfg) if shear else 0.0
    if args.side is None:
        e, a = np.radians(elev), np.radians(azim)
        eye = np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])
        panel_w, panel_h = panel or (3.0, 3.4)
    else:
        h_axis, v_axis, sign = SIDES[args.side]
        eye = np.zeros(3)
        eye["xyz".index(args.side)] = sign
        extent = upper - lower
        width = 6.5 if extent[h_axis] >= extent[v_axis] else 3.5
        panel_w, panel_h = panel or (width, width * extent[v_axis] / extent[h_axis] + 1.1)
    light = eye + 0.6 * np.array([0.0, 0.0, 1.0] if args.side != "z" else [0.0, 1.0, 0.0])
    light /= np.linalg.norm(light)
    count = max(len({m for m, _, _ in ms}) for _, _, ms in data)
    several = count > 1
    palette = matplotlib.colormaps["tab10" if count <= 10 else "tab20"]

    ncols = args.columns or len(data)
    nrows = -(-len(data) // ncols)
    fig = plt.figure(figsize=(panel_w * ncols, panel_h * nrows + 0.35))
    for n, (i, time, membranes) in enumerate(data):
        polys, colors = [], []
        for m, nodes, tris in membranes:
            xyz = nodes[tris]
            polys.append(xyz)
            colors.append(shaded_colors(xyz, palette(m % palette.N) if several else "tab:red", light))
        polys, colors = np.concatenate(polys), np.concatenate(colors)
        edges = (0, 0, 0, 0.2) if len(polys) <= 30000 else "none"
        if args.side is None:
            ax = fig.add_subplot(nrows, ncols, n + 1, projection="3d")
            ax.set_proj_type("ortho")
            ax.add_collection3d(Poly3DCollection(polys, facecolors=colors, edgecolors=edges, linewidths=0.15))
            if args.box:
                draw_box(ax, lower, upper)
            ax.set_xlim(lower[0], upper[0])
            ax.set_ylim(lower[1], upper[1])
            ax.set_zlim(lower[2], upper[2])
            ax.set_box_aspect(tuple(upper - lower))
            ax.view_init(elev=elev, azim=azim)
            ax.set_xlabel("x" + unit, fontsize=8, labelpad=-2)
            ax.set_ylabel("y" + unit, fontsize=8, labelpad=-2)
            ax.set_zlabel("z" + unit, fontsize=8, labelpad=-2)
            ax.tick_params(labelsize=6, pad=0)
            ax.locator_params(nbins=4)
        else:
            ax = fig.add_subplot(nrows, ncols, n + 1)
            depth = polys[:, :, "xyz".index(args.side)].mean(axis=1) * sign
            order = np.argsort(depth, kind="stable")  # far (small depth * sign) first
            faces = PolyCollection(polys[order][:, :, [h_axis, v_axis]], facecolors=colors[order],
                                   edgecolors=edges, linewidths=0.15)
            ax.add_collection(faces)
            if args.box:
                outline = plt.Rectangle((lower[h_axis], lower[v_axis]), upper[h_axis] - lower[h_axis],
                                        upper[v_axis] - lower[v_axis], fill=False, color="k", lw=1)
                ax.add_patch(outline)
                faces.set_clip_path(outline)
            pad = 0.02 * (upper - lower).max()
            ax.set_xlim(lower[h_axis] - pad, upper[h_axis] + pad)
            ax.set_ylim(lower[v_axis] - pad, upper[v_axis] + pad)
            ax.set_aspect("equal")
            ax.set_xlabel(AXES[h_axis] + unit, fontsize=8)
            ax.set_ylabel(AXES[v_axis] + unit, fontsize=8)
            ax.tick_params(labelsize=7)
        if labels is not None:
            title = labels[n]
        elif shear:
            title = f"k t = {k * time:.3g} (frame {i})"
        else:
            title = f"t = {time:.4g}{' s' if micro else ''} (frame {i})"
        ax.set_title(title, fontsize=9)
    default_title = (f"{count} membranes" if count > 1 else "Membrane") + f", {pc.label_of(cfg, args.run_dir)}"
    fig.suptitle(args.title or default_title, fontsize=10)
    if args.side is None:
        fig.subplots_adjust(left=0.01, right=0.97, bottom=0.03, top=1 - 0.5 / (panel_h * nrows + 0.35),
                            wspace=0.12, hspace=0.15)
    else:
        fig.tight_layout(rect=(0, 0, 1, 1 - 0.35 / (panel_h * nrows + 0.35)))
    out = args.output or os.path.join(args.run_dir, "shapes.png")
    fig.savefig(out, dpi=pc.DPI)
    print(f"{out}: frames {frames} at times {[round(d[1], 6) for d in data]}, {count} membrane(s) per frame")


if __name__ == "__main__":
    main()
