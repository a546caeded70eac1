#!/usr/bin/python3
"""Membrane positions of runs against a reference run at the same time: the time-step error of each.

Usage: /usr/bin/python3 scripts/compare_runs.py REFERENCE_DIR RUN_DIR [RUN_DIR ...]

Each DIR is the --out directory of an `immerse run`; its checkpoint.h5 (written at the end of every run) holds the
membrane positions. Every run must have the same membranes (node counts) and end at the same time as the reference.
For each run, one line: its time step, steps, fluid solves (from diagnostics.csv, when it has a row per step), and
the distance of its nodes from the reference's: the largest and the root-mean-square over all nodes of all
membranes, in metres and in grid spacings h (the smallest of domain.L / grid.n), and the largest distance between a
membrane's centroid (mean of its nodes) and the reference's. Between consecutive runs whose steps halve or double,
the observed order of the root-mean-square error, log(e2/e1)/log(dt2/dt1).
"""
import math
import os
import sys

import h5py
import numpy as np

import plot_common as pc


def read_run(run_dir):
    path = os.path.join(run_dir, "checkpoint.h5")
    if not os.path.isfile(path):
        pc.fail(f"{path} not found: is {run_dir} the --out directory of an 'immerse run'?")
    with h5py.File(path, "r") as f:
        time = float(f["double/fluid.time"][()])
        steps = int(f["int64/step"][()])
        names = sorted((n for n in f["arrays"] if n.startswith("membrane[") and n.endswith(".positions")),
                       key=lambda n: int(n[len("membrane["):n.index("]")]))
        if not names:
            pc.fail(f"{path}: no membrane positions")
        X = [np.asarray(f["arrays/" + n]).reshape(-1, 3) for n in names]
    config = pc.read_config(run_dir)
    solves = None  # counted when diagnostics.csv has a row per step
    if config["output"]["diagnostics_every"] == 1:
        diag = pc.read_diagnostics(run_dir)
        solves = int(np.sum(diag["fluid_solves"][diag["step"] > 0]))
    return {"time": time, "X": X, "config": config, "steps": steps, "solves": solves,
            "dt": float(config["time"]["dt"])}


def main(argv):
    if len(argv) < 3:
        pc.fail("usage: compare_runs.py REFERENCE_DIR RUN_DIR [RUN_DIR ...]")
    ref = read_run(argv[1])
    domain, grid = ref["config"]["domain"], ref["config"]["grid"]
    h = min(domain["Lx"] / grid["nx"], domain["Ly"] / grid["ny"], domain["Lz"] / grid["nz"])
    print(f"reference {argv[1]}: {ref['config']['time']['scheme']}, dt = {ref['dt']:.6g} s, {ref['steps']} steps, "
          f"t = {ref['time']:.6g} s, {len(ref['X'])} membranes, h = {h:.6g} m", flush=True)
    previous = None
    for run_dir in argv[2:]:
        run = read_run(run_dir)
        if len(run["X"]) != len(ref["X"]) or any(a.shape != b.shape for a, b in zip(run["X"], ref["X"])):
            pc.fail(f"{run_dir}: its membranes differ from the reference's (count or node counts)")
        if not math.isclose(run["time"], ref["time"], rel_tol=1e-9):
            pc.fail(f"{run_dir}: ends at t = {run['time']:.9g} s, the reference at {ref['time']:.9g} s")
        d = np.concatenate([np.linalg.norm(a - b, axis=1) for a, b in zip(run["X"], ref["X"])])
        centroid = max(np.linalg.norm(a.mean(axis=0) - b.mean(axis=0)) for a, b in zip(run["X"], ref["X"]))
        rms = math.sqrt(float(np.mean(d * d)))
        solves = "" if run["solves"] is None else \
            f", {run['solves']} fluid solves ({run['solves'] / run['steps']:.2f} per step)"
        line = (f"{run_dir}: {run['config']['time']['scheme']}, dt = {run['dt']:.6g} s, {run['steps']} steps{solves}; "
                f"node distance max {d.max():.4g} m ({d.max() / h:.4g} h), rms {rms:.4g} m ({rms / h:.4g} h); "
                f"centroid max {centroid:.4g} m ({centroid / h:.4g} h)")
        halved_or_doubled = previous and any(math.isclose(run["dt"], f * previous["dt"], rel_tol=1e-9)
                                             for f in (0.5, 2))
        if halved_or_doubled and previous["rms"] > 0 and rms > 0:
            line += f"; order {math.log(rms / previous['rms']) / math.log(run['dt'] / previous['dt']):.2f}"
        print(line)
        previous = {"rms": rms, "dt": run["dt"]}


if __name__ == "__main__":
    main(sys.argv)
