#!/usr/bin/python3
"""Processes against threads: the same run on P MPI processes of one thread and on one process of P threads.

    /usr/bin/python3 bench/processes.py                  §4.4 at the paper's size (scenarios/rbc_channel.toml),
                                                         to t = 0.05 s (112 steps), 2 x 1 against 1 x 2
    /usr/bin/python3 bench/processes.py --end 9e-3       the first 20 steps only
    /usr/bin/python3 bench/processes.py --scenario scenarios/rbc_channel_quick.toml --processes 2

Each configuration runs `--repeat` times (default 2), alternating, without frames or checkpoints; the fastest wall
time of the whole program is kept. Printed: both wall times, their ratio (P processes / P threads; goal <= 1.10,
docs/performance.md) and the fluid solves per step of each run, which must agree (the same mathematics). Needs an
otherwise idle machine; the raw output of every run goes to build/release/bench/results/processes/.
"""
import argparse
import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
IMMERSE = ROOT / "build/release/immerse"
OUT = ROOT / "build/release/bench/results/processes"
NO_OUTPUT = ["output.fields_every=0", "output.checkpoint_every=0"]
MPI_ENV = {"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1", "OMPI_MCA_plm": "isolated"}


def run(name, scenario, end, processes, threads, index):
    out = OUT / f"{name}.{index}"
    shutil.rmtree(out, ignore_errors=True)
    sets = NO_OUTPUT + ([f"time.end={end}"] if end else [])
    cmd = [str(IMMERSE), "run", str(scenario), "--out", str(out)]
    for s in sets:
        cmd += ["--set", s]
    if processes > 1:
        cmd = ["mpiexec", "-n", str(processes), "--bind-to", "core"] + cmd
    env = dict(os.environ, OMP_NUM_THREADS=str(threads), **MPI_ENV)
    start = time.perf_counter()
    p = subprocess.run(cmd, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - start
    (OUT / f"{name}.{index}.log").write_text(p.stdout + p.stderr)
    if p.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed with exit {p.returncode}:\n{p.stderr}")
    return wall, fluid_solves_per_step(out / "diagnostics.csv")


def fluid_solves_per_step(csv):
    lines = csv.read_text().splitlines()
    header = lines[0].split(",")
    if "fluid_solves" not in header:
        return float("nan")
    col = header.index("fluid_solves")
    rows = [line.split(",") for line in lines[1:] if line]
    steps = [r for r in rows if int(float(r[header.index("step")])) > 0]
    return sum(float(r[col]) for r in steps) / max(1, len(steps))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenario", default=str(ROOT / "scenarios/rbc_channel.toml"))
    ap.add_argument("--end", type=float, default=None, help="time.end (default: the scenario's)")
    ap.add_argument("--processes", type=int, default=2)
    ap.add_argument("--repeat", type=int, default=2)
    a = ap.parse_args()
    OUT.mkdir(parents=True, exist_ok=True)
    P = a.processes
    best = {}
    solves = {}
    for i in range(a.repeat):
        for name, procs, threads in ((f"{P}x1", P, 1), (f"1x{P}", 1, P)):
            wall, s = run(name, a.scenario, a.end, procs, threads, i)
            print(f"  {name} run {i + 1}: {wall:.1f} s, {s:.2f} fluid solves per step", flush=True)
            best[name] = min(best.get(name, float("inf")), wall)
            solves[name] = s
    ratio = best[f"{P}x1"] / best[f"1x{P}"]
    print(f"{Path(a.scenario).name}: {P} processes x 1 thread {best[f'{P}x1']:.1f} s, "
          f"1 process x {P} threads {best[f'1x{P}']:.1f} s, ratio {ratio:.3f} (goal <= 1.10)")
    print(f"fluid solves per step: {solves[f'{P}x1']:.2f} and {solves[f'1x{P}']:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
