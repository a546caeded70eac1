#!/usr/bin/python3
"""Relative viscosity of a suspension in plane Couette flow against its volume fraction (hematocrit).

Usage: /usr/bin/python3 scripts/plot_suspension_shear.py RUN_DIR [RUN_DIR ...] [-o PNG] [--from-kt KT] [--title T]
Runs of scenarios/suspension_shear.toml or suspension_shear_quick.toml (scenario.kind = "suspension_shear"), one per
hematocrit. For each run, from diagnostics.csv: the volume fraction H (its mean over the run) and the relative
viscosity eta_rel = (tau_lower + tau_upper) / (2 mu k), averaged in time (trapezoidal weights, so that halved steps
do not count more) over k t >= KT (default: the second half of the run), with the standard error of that mean from
the means of four blocks of equal duration (the wall stress is correlated over a few shear times, so single steps
are not independent samples).
Beside them, the relative apparent viscosity of human red cells in plasma-like media measured in tubes at high shear
rates (>= 50 1/s), as fitted by Pries, Neuhaus & Gaehtgens (1992, Am. J. Physiol. 263:H1770):
    eta_rel(H, D) = 1 + (eta_045(D) - 1) ((1 - H)^C - 1) / ((1 - 0.45)^C - 1),
    eta_045(D) = 220 exp(-1.3 D) + 3.2 - 2.44 exp(-0.06 D^0.645),
    C(D) = (0.8 + exp(-0.075 D)) (-1 + 1 / (1 + 1e-11 D^12)) + 1 / (1 + 1e-11 D^12),   D in micrometres,
drawn for wide tubes (D -> infinity: eta_045 = 3.2, C = -0.8, bulk blood) and for a tube as wide as the run's gap
(D = Lz), the two bounds a sheared layer of a few cell diameters falls between.
Left panel: eta_rel against H; right panel: eta_rel against k t for each run, with its averaging window.
Default PNG: suspension_shear.png in the first RUN_DIR.
"""
import argparse
import os

import matplotlib.pyplot as plt
import numpy as np

import plot_common as pc


def pries(h, d_um):
    """Relative apparent viscosity of blood at hematocrit h in a tube of diameter d_um micrometres (np.inf: wide)."""
    if np.isinf(d_um):
        eta45, c = 3.2, -0.8
    else:
        eta45 = 220 * np.exp(-1.3 * d_um) + 3.2 - 2.44 * np.exp(-0.06 * d_um ** 0.645)
        w = 1 / (1 + 1e-11 * d_um ** 12)
        c = (0.8 + np.exp(-0.075 * d_um)) * (-1 + w) + w
    return 1 + (eta45 - 1) * ((1 - h) ** c - 1) / ((1 - 0.45) ** c - 1)


def read_run(run_dir, from_kt):
    cfg = pc.read_config(run_dir)
    if pc.scenario_kind(cfg) != "suspension_shear":
        pc.fail(f"{run_dir}: scenario.kind is {pc.scenario_kind(cfg)!r}, not 'suspension_shear'")
    d = pc.read_diagnostics(run_dir)
    for name in ("kt", "volume_fraction", "relative_viscosity"):
        if name not in d:
            pc.fail(f"{run_dir}/diagnostics.csv has no column {name!r}")
    kt, eta = d["kt"], d["relative_viscosity"]
    start = 0.5 * kt[-1] if from_kt is None else from_kt
    window = kt >= start
    if window.sum() < 4:
        pc.fail(f"{run_dir}: {window.sum()} rows with k t >= {start:g}; at least 4 are needed (run longer or lower "
                "--from-kt)")
    t, e = kt[window], eta[window]
    # Time-weighted (trapezoidal) means: halved steps put rows closer together, not more weight.
    w = np.ones(1)
    if len(t) > 1:
        w = np.zeros(len(t))
        w[:-1] += 0.5 * np.diff(t)
        w[1:] += 0.5 * np.diff(t)
    edges = np.linspace(t[0], t[-1], 5)
    block = np.minimum(np.searchsorted(edges, t, side="right") - 1, 3)
    means = np.array([np.average(e[block == b], weights=w[block == b]) for b in range(4) if np.any(block == b)])
    m = cfg["membrane"][0] if cfg.get("membrane") else {}
    return {"dir": run_dir, "H": float(d["volume_fraction"].mean()), "kt": kt, "eta": eta, "start": start,
            "mean": float(np.average(e, weights=w)), "sem": float(means.std(ddof=1) / np.sqrt(len(means))),
            "gap_um": cfg["domain"]["Lz"] * 1e6,
            "cells": sum(1 for n in d if n.startswith("m") and n.endswith("_volume")) or ("volume" in d),
            "lambda": m.get("viscosity_ratio", 1.0), "resolution": pc.resolution_of(cfg) if m else ""}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run_dirs", nargs="+", metavar="RUN_DIR")
    parser.add_argument("-o", "--output", help="PNG to write (default suspension_shear.png in the first RUN_DIR)")
    parser.add_argument("--from-kt", type=float, help="start of the averaging window in k t (default: half the run)")
    parser.add_argument("--title", default="Red cells in plane Couette flow: relative viscosity", help="figure title")
    args = parser.parse_args()

    runs = sorted((read_run(d, args.from_kt) for d in args.run_dirs), key=lambda r: r["H"])
    gap = runs[0]["gap_um"]
    mixed = len({r["resolution"] for r in runs}) > 1  # runs on several grids or meshes: say which in the labels
    fig, (ax, ax_t) = plt.subplots(1, 2, figsize=(12.0, 4.6))
    h = np.linspace(0, 0.45, 91)
    ax.plot(h, pries(h, np.inf), "k-", lw=1, label="Pries et al. (1992), wide tubes")
    ax.plot(h, pries(h, gap), "k--", lw=1, label=f"Pries et al. (1992), tube of D = {gap:.3g} $\\mu$m")
    for i, r in enumerate(runs):
        wide, narrow = pries(r["H"], np.inf), pries(r["H"], gap)
        print(f"{r['dir']}: H = {r['H']:.4f} ({r['cells']} cells, lambda = {r['lambda']:g}, {r['resolution']}): "
              f"eta_rel = {r['mean']:.4f} +- {r['sem']:.4f} over k t = {r['start']:.3g} ... {r['kt'][-1]:.3g}; "
              f"Pries et al. (1992): {wide:.3f} (wide tubes), {narrow:.3f} (D = {r['gap_um']:.3g} um)")
        label = f"H = {r['H']:.2f}" + (f", {r['resolution']}" if mixed else "")
        ax.errorbar(r["H"], r["mean"], yerr=r["sem"], fmt="o", color=f"C{i}", ms=6, capsize=3,
                    label=r["resolution"] if mixed else None)
        ax_t.plot(r["kt"], r["eta"], "-", color=f"C{i}", lw=1, label=label)
        ax_t.axvspan(r["start"], r["kt"][-1], color=f"C{i}", alpha=0.05)
        ax_t.hlines(r["mean"], r["start"], r["kt"][-1], colors=f"C{i}", linestyles=":", lw=1.5)
    ax.set_xlabel("hematocrit H (volume fraction of cells)")
    ax.set_ylabel("relative viscosity $\\eta_{rel}$")
    ax.set_xlim(0, 0.45)
    ax.set_ylim(bottom=1.0)
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small", loc="lower right" if mixed else "upper left")
    ax.set_title("Mean over the averaging window" + ("" if mixed else f" ({runs[0]['resolution']})"), fontsize=10)
    ax_t.set_xlabel("dimensionless time k t")
    ax_t.set_ylabel("$\\eta_{rel}$ = wall stress / ($\\mu$ k)")
    ax_t.grid(alpha=0.3)
    ax_t.legend(fontsize="small")
    ax_t.set_title("Wall stress in time (shaded: averaging window)", fontsize=10)
    fig.suptitle(args.title)
    fig.tight_layout()
    out = args.output or os.path.join(args.run_dirs[0], "suspension_shear.png")
    fig.savefig(out, dpi=pc.DPI)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
