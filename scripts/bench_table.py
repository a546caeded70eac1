"""Prints the table of scripts/bench.sh from the results in DIR (Google Benchmark JSON of bench_fluid,
bench_coupling and bench_membrane, text of bench_oscillating): benchmark, measured figure, bound, ratio, goal, met.
Goals are those of docs/performance.md. Usage: /usr/bin/python3 scripts/bench_table.py DIR"""
import json
import os
import re
import sys


def load(directory, name):
    path = os.path.join(directory, name + ".json")
    if not os.path.exists(path) or os.path.getsize(path) == 0:  # (empty: the filter matched no case)
        return []
    with open(path) as f:
        return [b for b in json.load(f)["benchmarks"] if b.get("run_type", "iteration") == "iteration"]


def fmt(x):
    if x is None:
        return "-"
    if isinstance(x, str):
        return x
    return f"{x:.3g}" if abs(x) < 1e4 else f"{x:.3e}"


def row(rows, name, figure, bound, ratio, goal, met):
    rows.append((name, fmt(figure), fmt(bound), fmt(ratio), goal, "-" if met is None else ("yes" if met else "NO")))


def main(directory):
    rows = []
    # One fluid step against the FFTW transforms it performs (goal <= 1.5); 2-thread speedup (goal >= 1.7). Also one
    # trial of an implicit step (the step from a prepared force-independent part), against the same bound.
    for b in load(directory, "bench_fluid"):
        threads = int(re.search(r"threads:(\d+)", b["name"]).group(1))
        label = b.get("label", b["name"])
        kind = "fluid trial (prepared)" if b["name"].startswith("BM_FluidTrial") else "fluid step"
        ratio = b["ratio_to_transforms"]
        row(rows, f"{kind}, {label}, {threads} thr", f"{b['real_time']:.1f} ms", "FFTW transforms", ratio,
            "<= 1.5", ratio <= 1.5)
        if threads > 1 and "speedup" in b:
            row(rows, f"{kind}, {label}, speedup", b["speedup"], "-", "-", ">= 1.7", b["speedup"] >= 1.7)
    # Spreading / interpolation against the STREAM-triad bound (goal >= 0.5); 2-thread speedup (goal >= 1.7).
    rates = {}
    for b in load(directory, "bench_coupling"):
        name = b["name"].replace("/real_time", "")
        op, kernel, thr = name.split("/")
        threads = int(thr.split(":")[1])
        rates[(op, kernel, threads)] = b["nodes_per_s"]
        frac = b["fraction_of_stream_bound"]
        row(rows, f"{op} {kernel}, {threads} thr", f"{b['nodes_per_s_per_core']:.3g} nodes/s/core",
            f"{b['stream_bound_nodes_per_s']:.3g} nodes/s", frac, ">= 0.5", frac >= 0.5)
    for (op, kernel, threads), r in sorted(rates.items()):
        if threads > 1 and (op, kernel, 1) in rates:
            s = r / rates[(op, kernel, 1)]
            row(rows, f"{op} {kernel}, speedup", s, "-", "-", ">= 1.7", s >= 1.7)
    # Membrane forces: elements/s/core (goal 1e6, docs/performance.md) and 2-thread speedup.
    for b in load(directory, "bench_membrane"):
        threads = int(re.search(r"threads:(\d+)", b["name"]).group(1))
        label = b.get("label", b["name"])
        eps = b["elements/s/core"]
        row(rows, f"membrane force {label}, {threads} thr", f"{eps:.3g} elem/s/core", "-", "-", ">= 1e6",
            eps >= 1e6)
        if threads > 1:
            row(rows, f"membrane force {label}, speedup", b["speedup"], "-", "-", ">= 1.7", b["speedup"] >= 1.7)
    # Whole run of §4.1 at the quick size: fluid solves per JFNK step, explicit / JFNK time.
    path = os.path.join(directory, "bench_oscillating.txt")
    if os.path.exists(path):
        text = open(path).read()
        m = re.search(r"JFNK, dt = 4dx\s+([\d.]+)\s+([\d.]+)", text)
        if m:
            solves = float(m.group(2))
            row(rows, "JFNK step (4.1 quick, dt = 4dx)", f"{solves:.2f} fluid solves", "1 fluid step", solves,
                "<= 4 (4.4)", solves <= 4)
        m = re.search(r"ratio explicit / JFNK: ([\d.]+)", text)
        if m:
            row(rows, "explicit Euler / JFNK to t = 10 (4.1 quick)", float(m.group(1)), "-", "-", "-", None)
    # Whole run of §4.4 (bench_channel): each implicit scheme's wall time, fluid solves per step, explicit RK2 / it.
    for name, size in (("bench_channel_quick.txt", "quick"), ("bench_channel.txt", "paper size")):
        path = os.path.join(directory, name)
        if not os.path.exists(path):
            continue
        text = open(path).read()
        paper = size == "paper size"
        for m in re.finditer(r"^(JFNK|Anderson|L-BFGS): (\d+) steps in ([\d.]+) s \(([\d.]+) s/step\), "
                             r"per step ([\d.]+) fluid solves", text, re.MULTILINE):
            scheme, seconds, solves = m.group(1), float(m.group(3)), float(m.group(5))
            row(rows, f"4.4 {scheme} to t = 0.05 s ({size})", f"{seconds:.1f} s", "-", "-",
                "<= 120 s" if paper else "-", seconds <= 120 if paper else None)
            row(rows, f"{scheme} step (4.4 {size})", f"{solves:.2f} fluid solves", "1 fluid step", solves, "<= 4",
                solves <= 4)
        for m in re.finditer(r"ratio explicit / implicit \(([\w-]+)\): (at least |at most )?([\d.]+)", text):
            # A bound when the RK2 probes did not bracket the stable step within their budget.
            scheme, bound, ratio = m.group(1), m.group(2), float(m.group(3))
            shown = {"at least ": f">= {ratio}", "at most ": f"<= {ratio}"}.get(bound, ratio)
            undecided = (bound == "at least " and ratio < 43) or (bound == "at most " and ratio >= 43)
            met = None if undecided else ratio >= 43
            row(rows, f"explicit RK2 / {scheme} to t = 0.05 s (4.4 {size})", shown, "-", "-", ">= 43", met)
        m = re.search(r"peak resident memory: (\d+) MiB", text)
        if m and size == "paper size":
            mib = float(m.group(1))
            row(rows, "4.4 peak resident memory (paper size)", f"{mib:.0f} MiB", "-", "-", "<= 2048 MiB", mib <= 2048)
    head = ("benchmark", "measured", "bound", "ratio", "goal", "met?")
    widths = [max(len(r[i]) for r in rows + [head]) for i in range(len(head))]
    for r in [head, tuple("-" * w for w in widths)] + rows:
        print("  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip())


if __name__ == "__main__":
    main(sys.argv[1])
