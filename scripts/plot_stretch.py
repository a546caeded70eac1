#!/usr/bin/python3
"""Fig. 13 of the paper: axial and transverse diameters of a red blood cell vs the stretching force.

Usage: /usr/bin/python3 scripts/plot_stretch.py RUN_DIR [RUN_DIR ...] [-o PNG] [--experiment CSV | --no-experiment]
Each RUN_DIR is an rbc_stretch run (one per shear modulus scenario.mu0, read from its config.resolved.toml); its
stretch.csv (force_pN, axial_um, transverse_um: the steady diameters at each force of the sweep) is drawn as one
line style per run, axial and transverse alike: the paper's (dotted, solid, dash-dotted for mu0 = 4.8, 7.3, 10
uN/m) when every run has one of those moduli, else dotted, solid, dash-dotted, dashed in order of increasing mu0.
The optical-tweezers measurements of Mills et al. (2004), the paper's ref. [32], are drawn beside as symbols with
error bars, from scenarios/rbc_stretch_mills2004.csv (see the source stated in that file) unless --no-experiment or
another --experiment CSV with the same columns is given. Default PNG: stretch.png in the first RUN_DIR.
"""
import argparse
import os

import matplotlib.pyplot as plt
import numpy as np

import plot_common as pc

DEFAULT_EXPERIMENT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scenarios",
                                  "rbc_stretch_mills2004.csv")
EXPERIMENT_COLUMNS = ("force_pN", "axial_um", "axial_lo_um", "axial_hi_um",
                      "transverse_um", "transverse_lo_um", "transverse_hi_um")
STYLES = [":", "-", "-.", "--"]
PAPER_STYLES = {4.8: ":", 7.3: "-", 10.0: "-."}  # Fig. 13: dotted, solid, dash-dotted for mu0 = 4.8, 7.3, 10 uN/m


def read_experiment(path):
    """The measured diameters: a dict column -> numpy array (lines starting with '#' are comments)."""
    if not os.path.isfile(path):
        pc.fail(f"--experiment {path}: file not found")
    with open(path) as f:
        lines = [line for line in f if not line.lstrip().startswith("#")]
    data = np.genfromtxt(lines, delimiter=",", names=True, ndmin=1)
    missing = [c for c in EXPERIMENT_COLUMNS if c not in (data.dtype.names or ())]
    if data.size == 0 or missing:
        pc.fail(f"--experiment {path}: expected a header with columns {','.join(EXPERIMENT_COLUMNS)} and rows; "
                f"missing {','.join(missing) or 'rows'}")
    return {c: np.asarray(data[c], dtype=float) for c in EXPERIMENT_COLUMNS}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run_dirs", nargs="+", metavar="RUN_DIR")
    parser.add_argument("-o", "--output", help="PNG to write (default stretch.png in the first RUN_DIR)")
    parser.add_argument("--experiment", default=DEFAULT_EXPERIMENT,
                        help="CSV of measured diameters (default scenarios/rbc_stretch_mills2004.csv)")
    parser.add_argument("--no-experiment", action="store_true", help="draw the simulations only")
    args = parser.parse_args()

    runs = []
    for run_dir in args.run_dirs:
        cfg = pc.read_config(run_dir)
        if pc.scenario_kind(cfg) != "rbc_stretch":
            pc.fail(f"{run_dir}: scenario.kind is {pc.scenario_kind(cfg)!r}, expected 'rbc_stretch'")
        runs.append((cfg["scenario"]["mu0"], run_dir, cfg))
    runs.sort(key=lambda r: r[0])
    if len(runs) > len(STYLES):
        pc.fail(f"{len(runs)} runs given: at most {len(STYLES)} (one line style each)")

    moduli = [round(mu0 * 1e6, 6) for mu0, _, _ in runs]
    paper = all(m in PAPER_STYLES for m in moduli) and len(set(moduli)) == len(moduli)
    fig, ax = plt.subplots(figsize=(7.2, 6.0))
    for i, (mu0, run_dir, cfg) in enumerate(runs):
        force, axial, transverse = pc.read_stretch(run_dir)
        style = PAPER_STYLES[round(mu0 * 1e6, 6)] if paper else STYLES[i]
        ax.plot(force, axial, style, color="C0", lw=1.8, marker=".", ms=5)
        ax.plot(force, transverse, style, color="C3", lw=1.8, marker=".", ms=5)
        ax.plot([], [], style, color="k", lw=1.8, label=f"simulation, {pc.label_of(cfg, run_dir)}")
        rows = ", ".join(f"{f:g} pN: {a:.2f}/{t:.2f}" for f, a, t in zip(force, axial, transverse))
        print(f"{run_dir}: mu0 = {mu0 * 1e6:g} uN/m, axial/transverse (um) at {rows}")
    if not args.no_experiment:
        exp = read_experiment(args.experiment)
        f = exp["force_pN"]
        for name, color, marker in (("axial", "C0", "o"), ("transverse", "C3", "s")):
            mid = exp[f"{name}_um"]
            err = [mid - exp[f"{name}_lo_um"], exp[f"{name}_hi_um"] - mid]
            ax.errorbar(f, mid, yerr=err, fmt=marker, color=color, mfc="white", ms=5, capsize=2.5, lw=0.8)
        ax.plot([], [], "o", color="k", mfc="white", ms=5, label="experiment, Mills et al. (2004)")
        print(f"{os.path.normpath(args.experiment)}: {f.size} measured forces, {f.min():g}-{f.max():g} pN")
    ax.plot([], [], "-", color="C0", lw=6, alpha=0.6, label="axial diameter")
    ax.plot([], [], "-", color="C3", lw=6, alpha=0.6, label="transverse diameter")
    ax.set_xlabel("stretching force (pN)")
    ax.set_ylabel("diameter ($\\mu$m)")
    ax.set_xlim(left=-5)
    ax.set_ylim(bottom=0)
    ax.set_title("Red blood cell stretched by optical tweezers")
    ax.grid(alpha=0.3)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.13), fontsize="small", ncol=2)
    fig.tight_layout()
    out = args.output or os.path.join(args.run_dirs[0], "stretch.png")
    fig.savefig(out, dpi=pc.DPI)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
