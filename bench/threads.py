#!/usr/bin/python3
"""Thread benchmark: whole runs with one thread, two threads and the default thread count, on idle cores and with
one core kept busy by another process, and the ratios the performance page states.

    /usr/bin/python3 bench/threads.py               every scenario's quick form, the capsule relaxing in a periodic
                                                    box (bench/capsule_relax.toml, dt = 0.02 and 0.005) and the
                                                    paper-size capsule in shear and red-cell channel, cut to a few
                                                    steps (about 15 minutes)
    /usr/bin/python3 bench/threads.py --full        the paper-size runs whole (about 25 more minutes)
    /usr/bin/python3 bench/threads.py --only NAME   the cases whose name contains NAME

Columns: wall time of the whole process (seconds) with OMP_NUM_THREADS=1, =2 and unset (the default: the count
chosen by measurement, ThreadGovernor); then the same three with a busy loop running in another process. Ratios:
default / one thread (goal <= 1), one / two threads (goal >= 1.6 on the paper-size runs), default with the busy
core / one thread on idle cores (goal <= 1.3). Each configuration runs `--repeat` times (default 2), alternating,
and the fastest is kept. Needs an otherwise idle machine; the raw output of every run goes to
build/release/bench/results/threads/.
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
OUT = ROOT / "build/release/bench/results/threads"
NO_OUTPUT = ["output.fields_every=0", "output.checkpoint_every=0"]


def cases(full):
    s = ROOT / "scenarios"
    relax = ROOT / "bench/capsule_relax.toml"
    quick = [
        ("capsule_shear_quick (default experiment)", s / "capsule_shear_quick.toml", []),
        ("bending_shear_quick", s / "bending_shear_quick.toml", []),
        ("oblate_shear_quick", s / "oblate_shear_quick.toml", []),
        ("oscillating_membrane_quick", s / "oscillating_membrane_quick.toml", []),
        ("rbc_stretch_quick, 100 steps", s / "rbc_stretch_quick.toml", ["time.end=0.05"]),
        ("rbc_channel_quick, 40 steps", s / "rbc_channel_quick.toml", ["time.end=0.018"]),
        ("capsule relaxing, dt = 0.02", relax, []),
        ("capsule relaxing, dt = 0.005", relax, ["time.dt=0.005"]),
    ]
    paper = [
        ("capsule_shear (paper size)" + ("" if full else ", 25 steps"), s / "capsule_shear.toml",
         [] if full else ["scenario.kt_end=0.5"]),
        ("rbc_channel (paper size)" + ("" if full else ", 20 steps"), s / "rbc_channel.toml",
         [] if full else ["time.end=0.009"]),
    ]
    return [(n, f, sets + NO_OUTPUT, False) for n, f, sets in quick] + [(n, f, sets + NO_OUTPUT, True)
                                                                         for n, f, sets in paper]


def run(name, file, sets, threads, busy, tag):
    env = dict(os.environ)
    env.pop("OMP_NUM_THREADS", None)
    if threads:
        env["OMP_NUM_THREADS"] = str(threads)
    out = OUT / tag
    if out.exists():
        shutil.rmtree(out)
    cmd = [str(IMMERSE), "run", str(file), "--out", str(out)]
    for s in sets:
        cmd += ["--set", s]
    hog = subprocess.Popen([sys.executable, "-c", "while True: pass"]) if busy else None
    try:
        t0 = time.perf_counter()
        p = subprocess.run(cmd, env=env, capture_output=True, text=True)
        wall = time.perf_counter() - t0
    finally:
        if hog:
            hog.kill()
            hog.wait()
    (OUT / (tag + ".stdout")).write_text(p.stdout + p.stderr)
    shutil.rmtree(out, ignore_errors=True)
    if p.returncode != 0:
        sys.exit(f"{name}: immerse exited {p.returncode}: {(p.stderr or p.stdout).strip().splitlines()[-1:]}")
    chosen = re.search(r"1 thread for ([0-9.]+) %", p.stdout)
    return wall, float(chosen.group(1)) if chosen else None


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--full", action="store_true", help="the paper-size runs whole")
    ap.add_argument("--only", default="", help="only the cases whose name contains this")
    ap.add_argument("--repeat", type=int, default=2, help="runs of each configuration (the fastest is kept)")
    a = ap.parse_args()
    if not IMMERSE.exists():
        sys.exit(f"{IMMERSE} is missing: build it first (bash scripts/build.sh)")
    OUT.mkdir(parents=True, exist_ok=True)
    load = open("/proc/loadavg").read().split()[:3]
    print(f"machine: {os.cpu_count()} CPUs, load average {' '.join(load)} at start")
    configs = [("1", 1, False), ("2", 2, False), ("default", None, False),
               ("1 busy", 1, True), ("2 busy", 2, True), ("default busy", None, True)]
    header = ("case", "1 thr", "2 thr", "default", "1 busy", "2 busy", "def. busy", "def/1", "1/2", "busy def/1",
              "1 thr chosen (idle/busy)")
    rows = []
    worst = {"def/1": 0.0, "busy": 0.0, "paper 1/2": float("inf")}
    for i, (name, file, sets, paper) in enumerate(cases(a.full)):
        if a.only and a.only not in name:
            continue
        best = {}
        chosen = {}
        for r in range(a.repeat):
            for label, threads, busy in configs:
                tag = f"case{i}_{label.replace(' ', '_')}_{r}"
                wall, one = run(name, file, sets, threads, busy, tag)
                best[label] = min(best.get(label, float("inf")), wall)
                if one is not None:
                    chosen[label] = one
        d1 = best["default"] / best["1"]
        s12 = best["1"] / best["2"]
        b1 = best["default busy"] / best["1"]
        worst["def/1"] = max(worst["def/1"], d1)
        worst["busy"] = max(worst["busy"], b1)
        if paper:
            worst["paper 1/2"] = min(worst["paper 1/2"], s12)
        rows.append((name, *(f"{best[c[0]]:.2f}" for c in configs), f"{d1:.2f}", f"{s12:.2f}", f"{b1:.2f}",
                     f"{chosen.get('default', 0):.0f} % / {chosen.get('default busy', 0):.0f} %"))
        print(" | ".join(rows[-1]), flush=True)
    print()
    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    for r in rows:
        print("| " + " | ".join(r) + " |")
    print()
    print(f"largest default / one thread: {worst['def/1']:.2f} (goal <= 1)")
    print(f"largest default with a busy core / one thread idle: {worst['busy']:.2f} (goal <= 1.3)")
    if worst["paper 1/2"] != float("inf"):
        print(f"smallest two-thread speedup on the paper-size runs: {worst['paper 1/2']:.2f} (goal >= 1.6)")


if __name__ == "__main__":
    main()
