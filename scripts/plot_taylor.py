#!/usr/bin/python3
"""Figs. 7, 8-10 and 11 of the paper: the Taylor shape parameter D_xz = (L - B)/(L + B) vs k t, for one or several runs.

Usage: /usr/bin/python3 scripts/plot_taylor.py RUN_DIR [RUN_DIR ...] [-o PNG] [--membrane I] [--theta]
                                               [--panel-per-G] [--title TEXT]
Runs of the shear scenarios capsule_shear (Fig. 7), oblate_shear (Figs. 8-9) and bending_shear (Fig. 11). From each
run's config.resolved.toml: the shear rate k = (boundary.z_upper_velocity[0] - boundary.z_lower_velocity[0]) /
domain.Lz and the legend (scenario.G; scenario.aspect_ratio = b/a for oblate_shear; scenario.kappa_B_hat for
bending_shear). Each capsule_shear run gets the small-deformation theory D = 25G/4 (docs/theory/conventions.md; initially
spherical neo-Hookean capsule without bending, viscosity ratio 1) as a dashed line of its colour up to G = 0.05
(it is printed for every G); the theory does
not apply to oblate or bending capsules and the paper draws none there. When the runs differ in kappa_B_hat, the
line width grows with kappa_B_hat, as in Fig. 11. --panel-per-G draws one panel per value of G (Fig. 11 a, b).
With --theta a second row of panels shows the inclination theta (for capsule_shear against its small-deformation
value pi/4 - 97G/16). Beside capsule_shear runs the published steady values of scenarios/capsule_shear_published.csv
(boundary elements, Ramanujan & Pozrikidis 1998, and two immersed-boundary front-tracking codes) are drawn as
markers at the end of the run, in the run's colour (--no-published leaves them out). A run that stopped before scenario.kt_end (e.g. an element inverted) says so in the legend.
Runs with the same groups (a refinement study, Fig. 10) are told apart by their grid and node count.
Default PNG: taylor.png in the first RUN_DIR.
"""
import argparse
import os

import matplotlib.pyplot as plt
import numpy as np

import plot_common as pc

PUBLISHED = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scenarios", "capsule_shear_published.csv")
THEORY_G_MAX = 0.05  # the small-deformation lines are drawn up to this G (beyond, 25G/4 is far off the curves)
METHODS = {  # marker and legend of each method in capsule_shear_published.csv
    "bem": ("o", "boundary elements (Ramanujan & Pozrikidis 1998)"),
    "ib_front_tracking": ("s", "IB front tracking (Doddi & Bagchi 2008)"),
    "adaptive_front_tracking": ("^", "adaptive front tracking (Huet & Wachs 2023)"),
}


def read_published(path):
    """Rows (G, D_xz, method) of the published steady values."""
    rows = []
    with open(path) as f:
        lines = [line for line in f if line.strip() and not line.startswith("#")]
    for line in lines[1:]:
        G, D, method = line.strip().split(",")
        if method not in METHODS:
            pc.fail(f"{path}: unknown method {method!r}, expected one of {', '.join(METHODS)}")
        rows.append((float(G), float(D), method))
    return rows

TITLES = {
    "capsule_shear": "Initially spherical neo-Hookean capsule in simple shear",
    "oblate_shear": "Oblate spheroidal capsule in simple shear",
    "bending_shear": "Spherical capsule with bending stiffness in simple shear",
}


def read_run(run_dir):
    cfg = pc.read_config(run_dir)
    kind = pc.scenario_kind(cfg)
    if kind not in pc.SHEAR_KINDS:
        pc.fail(f"{run_dir}: scenario.kind is {kind!r}, expected one of {', '.join(pc.SHEAR_KINDS)}")
    k = pc.shear_rate(cfg)
    if k == 0.0:
        pc.fail(f"{run_dir}: the z walls do not move (k = 0): not a shear run")
    sc = cfg["scenario"]
    return {"dir": run_dir, "cfg": cfg, "kind": kind, "k": k, "G": sc["G"],
            "ba": sc["aspect_ratio"] if kind == "oblate_shear" else 1.0,
            "kappa": sc["kappa_B_hat"] if kind == "bending_shear" else 0.0}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run_dirs", nargs="+", metavar="RUN_DIR")
    parser.add_argument("-o", "--output", help="PNG to write (default taylor.png in the first RUN_DIR)")
    parser.add_argument("--membrane", type=int, default=0, help="membrane index (default 0)")
    parser.add_argument("--theta", action="store_true", help="add panels with the inclination theta")
    parser.add_argument("--panel-per-G", action="store_true", help="one panel per value of G (Fig. 11 a, b)")
    parser.add_argument("--title", help="figure title (default: from the scenario kind)")
    parser.add_argument("--no-published", action="store_true",
                        help="leave out the published steady values beside capsule_shear runs")
    args = parser.parse_args()
    published = [] if args.no_published else read_published(PUBLISHED)

    runs = sorted((read_run(d) for d in args.run_dirs), key=lambda r: (r["G"], -r["ba"], r["kappa"]))
    kinds = sorted({r["kind"] for r in runs})
    title = args.title or (TITLES[kinds[0]] if len(kinds) == 1 else "Capsules in simple shear")
    groups = sorted({r["G"] for r in runs}) if args.panel_per_G else [None]
    # Line width grows with kappa_B_hat (Fig. 11): rank among the distinct values in the plot.
    kappas = sorted({r["kappa"] for r in runs})
    width = {kp: 1.2 + 1.1 * i for i, kp in enumerate(kappas)} if len(kappas) > 1 else {kappas[0]: 1.5}

    ncols, nrows = len(groups), 2 if args.theta else 1
    fig, axes = plt.subplots(nrows, ncols, figsize=(0.6 + 5.8 * ncols, 4.2 * nrows), squeeze=False)
    for col, group in enumerate(groups):
        ax, ax_theta = axes[0][col], (axes[1][col] if args.theta else None)
        members = [r for r in runs if group is None or r["G"] == group]
        theory = False
        methods_drawn = set()
        for i, r in enumerate(members):
            diag = pc.read_diagnostics(r["dir"])
            kt = r["k"] * diag["time"]
            D = pc.membrane_column(diag, "D_xz", args.membrane)
            theta = pc.membrane_column(diag, "theta", args.membrane)
            color, lw = f"C{i}", width[r["kappa"]]
            label = pc.label_of(r["cfg"], r["dir"])
            if sum(pc.label_of(m["cfg"], m["dir"]) == label for m in members) > 1:  # a refinement study (Fig. 10)
                label += f" ({pc.resolution_of(r['cfg'], args.membrane)})"
            sc = r["cfg"]["scenario"]
            if kt[-1] < sc["kt_end"] - 0.5 * sc["k_dt"]:  # the run stopped early (e.g. a mesh element inverted)
                label += f" (run stopped at k t = {kt[-1]:.3g})"
                print(f"warning: {r['dir']} ends at k t = {kt[-1]:.4g}, before scenario.kt_end = {sc['kt_end']:g}")
            ax.plot(kt, D, "-", color=color, lw=lw, label=label)
            if ax_theta is not None:
                ax_theta.plot(kt, theta, "-", color=color, lw=lw, label=label)
            # The oblate capsule's D_xz oscillates: report the mean and range over the second half of the run.
            late = kt >= 0.5 * kt[-1]
            plain = label.replace("$", "").replace("\\hat{\\kappa}_B", "kappa_B_hat")
            line = (f"{r['dir']}: {plain}, k = {r['k']:g} 1/s, kt_end = {kt[-1]:.3g}: "
                    f"D_xz = {D[-1]:.4f} (second half: mean {D[late].mean():.4f}, min {D[late].min():.4f}, "
                    f"max {D[late].max():.4f}), theta = {theta[-1]:.4f} rad")
            if r["kind"] == "capsule_shear":
                theory = True
                G = r["G"]
                if G <= THEORY_G_MAX:
                    ax.axhline(25.0 * G / 4.0, color=color, ls="--", lw=1)
                if ax_theta is not None and G <= THEORY_G_MAX:
                    ax_theta.axhline(np.pi / 4 - 97.0 * G / 16.0, color=color, ls="--", lw=1)
                line += (f"; theory 25G/4 = {25 * G / 4:.4f} (ratio {D[-1] / (25 * G / 4):.3f}), "
                         f"pi/4 - 97G/16 = {np.pi / 4 - 97 * G / 16:.4f}")
                # Published steady values at this G, spread a little along k t so that close values stay visible.
                here = [p for p in published if abs(p[0] - G) <= 1e-9 * G]
                for j, (_, Dp, method) in enumerate(here):
                    ax.plot(kt[-1] * (1.0 - 0.035 * j), Dp, METHODS[method][0], color=color, mfc="none", ms=7)
                    methods_drawn.add(method)
                    line += f"; {method} {Dp:.4f} (ours {100 * (D[late].mean() / Dp - 1):+.1f} %)"
            print(line)
        if theory:
            ax.plot([], [], "k--", lw=1, label="small-deformation theory 25G/4")
        for method in sorted(methods_drawn):
            ax.plot([], [], METHODS[method][0], color="k", mfc="none", ms=7, label=METHODS[method][1])
        ax.set_xlabel("dimensionless time k t")
        ax.set_ylabel("Taylor parameter $D_{xz}$")
        ax.set_xlim(left=0)
        ax.set_ylim(bottom=0)
        ax.set_title(title if group is None else f"({chr(ord('a') + col)}) G = {group:g}",
                     fontsize=11 if group is None else 10)
        ax.grid(alpha=0.3)
        ax.legend(loc="lower right", fontsize="small")
        if ax_theta is not None:
            if theory:
                ax_theta.plot([], [], "k--", lw=1, label="theory $\\pi/4 - 97G/16$")
            ax_theta.set_xlabel("dimensionless time k t")
            ax_theta.set_ylabel("inclination $\\theta$ (rad)")
            ax_theta.set_xlim(left=0)
            ax_theta.set_title("Inclination of the long axis to the flow", fontsize=10)
            ax_theta.grid(alpha=0.3)
            ax_theta.legend(fontsize="small")
    if args.panel_per_G:
        fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    out = args.output or os.path.join(args.run_dirs[0], "taylor.png")
    fig.savefig(out, dpi=pc.DPI)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
