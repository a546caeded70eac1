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


def read_diagnostics(run_dir):
    """diagnostics.csv as a dict column name -> numpy array (float)."""
    path = os.path.join(run_dir, "diagnostics.csv")
    if not os.path.isfile(path):
        fail(f"{path} not found: is {run_dir} the --out directory of an 'immerse run'?")
    data = np.genfromtxt(path, delimiter=",", names=True, ndmin=1)
    if data.size == 0:
        fail(f"{path} has no rows")
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


def label_of(cfg, run_dir):
    """A short legend label for a run."""
    kind = cfg.get("scenario", {}).get("kind", "none")
    if kind in ("capsule_shear", "oblate_shear", "bending_shear"):
        return f"G = {cfg['scenario']['G']:g}"
    if kind == "oscillating_membrane":
        return f"$\\mu$ = {cfg['fluid']['mu']:g}"
    return os.path.basename(os.path.normpath(run_dir))
