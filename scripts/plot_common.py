"""Shared readers for the plot_*.py scripts: one `immerse run` output directory.

A run directory holds diagnostics.csv (one row per step), config.resolved.toml (every key, resolved) and the
frames fields_NNNNNN.h5. Run the scripts with Debian's interpreter (/usr/bin/python3), which has matplotlib,
numpy and h5py.
"""
import glob
import os
import sys
import tomllib

import matplotlib

matplotlib.use("Agg")
import numpy as np  # noqa: E402

DPI = 100


def fail(message):
    """Stop with a one-line error."""
    sys.exit(f"error: {message}")


def read_config(run_dir):
    """The run's config.resolved.toml as a dict."""
    path = os.path.join(run_dir, "config.resolved.toml")
    if not os.path.isfile(path):
        fail(f"{path} not found: is {run_dir} the --out directory of an 'immerse run'?")
    with open(path, "rb") as f:
        return tomllib.load(f)


def read_table(run_dir, name, what, empty):
    """DIR/name (a CSV with a header) as a numpy record array; `what` names the run that writes it, `empty` says
    why it may have no rows."""
    path = os.path.join(run_dir, name)
    if not os.path.isfile(path):
        fail(f"{path} not found: is {run_dir} the --out directory of {what}?")
    data = np.genfromtxt(path, delimiter=",", names=True, ndmin=1)
    if data.size == 0:
        fail(f"{path} has no rows{empty}")
    return path, data


def read_diagnostics(run_dir):
    """diagnostics.csv as a dict column name -> numpy array (float)."""
    _, data = read_table(run_dir, "diagnostics.csv", "an 'immerse run'", "")
    return {name: np.asarray(data[name], dtype=float) for name in data.dtype.names}


def membrane_column(diag, name, membrane=0):
    """Column `name` of membrane `membrane`: plain with one membrane, prefixed m0_, m1_, ... with several."""
    for key in (f"m{membrane}_{name}", name):
        if key in diag:
            return diag[key]
    fail(f"diagnostics.csv has no column {name!r} for membrane {membrane}")


def frame_files(run_dir):
    """The run's frames fields_NNNNNN.h5, in order."""
    files = sorted(glob.glob(os.path.join(run_dir, "fields_*.h5")))
    if not files:
        fail(f"no fields_*.h5 frames in {run_dir}")
    return files


def shear_rate(cfg):
    """k = (velocity difference of the z walls along x) / Lz, in 1/s."""
    b = cfg["boundary"]
    return (b["z_upper_velocity"][0] - b["z_lower_velocity"][0]) / cfg["domain"]["Lz"]


SHEAR_KINDS = ("capsule_shear", "oblate_shear", "bending_shear")


def scenario_kind(cfg):
    """scenario.kind of a resolved configuration ("none" when absent)."""
    return cfg.get("scenario", {}).get("kind", "none")


def label_of(cfg, run_dir):
    """A short legend label for a run: its nondimensional groups (G, b/a, kappa_B_hat; mu; mu0)."""
    kind = scenario_kind(cfg)
    sc = cfg.get("scenario", {})
    if kind in SHEAR_KINDS:
        parts = [f"G = {sc['G']:g}"]
        if kind == "oblate_shear":
            parts.append(f"b/a = {sc['aspect_ratio']:g}")
        if kind == "bending_shear":
            parts.append(f"$\\hat{{\\kappa}}_B$ = {sc['kappa_B_hat']:g}")
        return ", ".join(parts)
    if kind == "oscillating_membrane":
        return f"$\\mu$ = {cfg['fluid']['mu']:g}"
    if kind == "rbc_stretch":  # the sweeps of Fig. 13 differ in modulus, area constraint and size
        label = f"$\\mu_0$ = {sc['mu0'] * 1e6:g} $\\mu$N/m"
        k_A = cfg["membrane"][0].get("area_modulus", 0.0)
        if k_A > 0:
            label += f", area modulus {k_A * 1e3:g} mN/m"
        return f"{label} ({resolution_of(cfg)})"
    if kind == "rbc_channel":
        return f"$\\mu_0$ = {sc['mu0'] * 1e6:g} $\\mu$N/m"
    return os.path.basename(os.path.normpath(run_dir))


def resolution_of(cfg, membrane=0):
    """The grid and the node count of membrane `membrane`, e.g. "64³ grid, 10,242 nodes" (generated meshes only)."""
    g = cfg["grid"]
    n = (g["nx"], g["ny"], g["nz"])
    grid = f"{n[0]}³ grid" if n[0] == n[1] == n[2] else f"{n[0]}×{n[1]}×{n[2]} grid"
    mesh = cfg["membrane"][membrane].get("mesh", {})
    per_level = {"icosahedral": 10, "octahedral": 4}.get(mesh.get("family"))
    if per_level is None:
        return grid
    return f"{grid}, {per_level * 4 ** (mesh['level'] + 1) + 2:,} nodes"


def parse_numbers(option, text):
    """Comma-separated numbers of a command-line option, e.g. --times 0,0.5,1."""
    try:
        return [float(s) for s in text.split(",")]
    except ValueError:
        fail(f"{option} {text!r}: expected comma-separated numbers such as 0,0.5,1")


def read_stretch(run_dir):
    """DIR/stretch.csv of an rbc_stretch run as (force_pN, axial_um, transverse_um) numpy arrays."""
    path, data = read_table(run_dir, "stretch.csv", "an rbc_stretch run",
                            " (the sweep stopped before its first force was steady)")
    for name in ("force_pN", "axial_um", "transverse_um"):
        if name not in data.dtype.names:
            fail(f"{path} has no column {name!r}")
    return tuple(np.asarray(data[n], dtype=float) for n in ("force_pN", "axial_um", "transverse_um"))
