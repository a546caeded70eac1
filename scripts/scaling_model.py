#!/usr/bin/python3
"""A performance model of one implicit time step of the red-cell channel distributed over MPI processes.

Usage: /usr/bin/python3 scripts/scaling_model.py RUN_DIR [--latency S] [--bandwidth B]
RUN_DIR is the --out folder of a one-process, one-thread run of the paper's channel, e.g.
    OMP_NUM_THREADS=1 build/release/immerse run scenarios/rbc_channel.toml --out out/model \
        --set time.end=0.009 --set output.fields_every=0 --set output.checkpoint_every=0 > out/model.log
(20 steps; its log must be saved as RUN_DIR.log beside the folder). From the log's profile line (milliseconds per
step of membrane forces, spreading, fluid, interpolation and the rest) and diagnostics.csv (fluid solves per step)
the model takes the cost per node and per grid cell of one residual evaluation, and the cost per unknown of the
rest of a step. It then predicts the wall time of one step on P processes for the 1,024-cell channel (8 x 4 x 4
copies of the 24 x 48 x 12 um duct of the paper's §4.4: a 512 x 512 x 128 grid, 1,024 cells of 10,242 nodes) with
  compute   the largest process's share: ceil(cells / P) cells and cells/P of the grid (membranes whole per process);
  halos     per evaluation, each membrane's force spread onto the blocks its kernel box overlaps (summed there) and
            the velocity copied back for the interpolation, and one plane of velocity for the fluid stencils four
            times per fluid step; two neighbours per process for slabs, four for pencils;
  FFTs      per fluid step four Helmholtz/Poisson solves of two transforms each; a distributed 3D transform costs
            one all-to-all among all P processes for slabs (FFTW-MPI with transposed output) and two among sqrt(P)
            processes each for pencils;
  reductions per evaluation, the Krylov and Anderson inner products: 3 all-reduces of log2(P) latency steps;
with a message costing latency + bytes / bandwidth. Slabs along the grid's longest axis allow at most its 512
planes; pencils split the two longest axes. Prints the strong scaling of the 1,024-cell channel (P = 32 ... 1,024) and the
weak scaling with one cell and 1/32 of the paper's duct per process (P = 32 ... 1,024, the duct copied along x and
y), each for slabs and pencils, with efficiency = T(P0) P0 / (T(P) P) (strong) or T(32) / T(P) (weak).
"""
import argparse
import csv
import math
import os
import re
import sys

NODES_PER_CELL = 10242
PAPER_GRID = (64, 128, 32)     # the §4.4 duct, 32 cells
PAPER_CELLS = 32


def fail(message):
    print(f"scaling_model: {message}", file=sys.stderr)
    sys.exit(2)


def measured_rates(run_dir):
    """Seconds per node and per grid cell of one residual evaluation, and per unknown of the rest of a step."""
    log = os.path.normpath(run_dir) + ".log"
    if not os.path.isfile(log):
        fail(f"{log}: no log beside the run folder (redirect the run's output there)")
    text = open(log).read()
    m = re.search(r"membrane forces ([\d.]+).*?contact ([\d.]+).*?spreading ([\d.]+).*?fluid ([\d.]+).*?"
                  r"interpolation ([\d.]+).*?the rest ([\d.]+)", text)
    if not m:
        fail(f"{log}: no profile line ('stepping took ..., ms per step ...'): did the run finish?")
    forces, contact, spread, fluid, interp, rest = (float(v) * 1e-3 for v in m.groups())
    threads = re.search(r"threads: (\d+)", text)
    if not threads or threads.group(1) != "1":
        fail(f"{log}: the model needs a one-thread run (OMP_NUM_THREADS=1)")
    with open(os.path.join(run_dir, "diagnostics.csv")) as f:
        rows = [r for r in csv.DictReader(f) if float(r["dt"]) > 0]
    if not rows:
        fail(f"{run_dir}/diagnostics.csv: no steps")
    evals = sum(float(r["fluid_solves"]) for r in rows) / len(rows)
    nodes = PAPER_CELLS * NODES_PER_CELL
    grid_cells = math.prod(PAPER_GRID)
    return {
        "evals": evals,
        "node": (forces + contact + spread + interp) / (evals * nodes),
        "cell": fluid / (evals * grid_cells),
        "rest": rest / (3 * nodes),
        "profile": (forces, contact, spread, fluid, interp, rest),
    }


def message(nbytes, latency, bandwidth):
    return latency + nbytes / bandwidth


def all_to_all(p, local_bytes, latency, bandwidth):
    """Pairwise exchange of local_bytes spread evenly over p processes (p - 1 messages sent by each)."""
    if p <= 1:
        return 0.0
    return (p - 1) * message(local_bytes / p, latency, bandwidth)


def process_grid(p, layout):
    """Processes along the split axes: (p,) for slabs, (q1, q2) with q1 q2 = p and q1 <= q2 for pencils."""
    if layout == "slab":
        return (p,)
    q1 = 2 ** (int(math.log2(p)) // 2)
    while p % q1:
        q1 //= 2
    return (q1, p // q1)


def step_time(rates, grid, cells, p, layout, latency, bandwidth):
    """Modelled seconds per step on p processes, with its parts; None when the layout cannot use p processes.

    Slabs split the longest axis; pencils split the two longest (the shortest stays whole for the first transform).
    """
    dims = sorted(grid, reverse=True)
    split = process_grid(p, layout)
    if any(q > n for q, n in zip(split, dims)):
        return None
    evals = rates["evals"]
    local_cells = math.prod(grid) / p
    nodes = math.ceil(cells / p) * NODES_PER_CELL
    compute = evals * (nodes * rates["node"] + local_cells * rates["cell"]) + 3 * nodes * rates["rest"]
    # The owner of a membrane spreads onto (and interpolates from) the box its kernel touches: about
    # (7.82 um / h + 2G) across the disc, i.e. 25 planes on each split axis at the paper's spacing (worst case:
    # the disc across the split), the part outside the owner's block going to the blocks it overlaps.
    box = 25 * 25 * 11
    overlapped, outside = 1, 1.0
    for q, n in zip(split, dims):
        thickness = n / q
        k = min(q, math.ceil(25 / thickness) + 1)
        overlapped *= k
        outside *= min(1.0, thickness / 25)
    outside = 1.0 - outside
    per_membrane = 2 * ((overlapped - 1) * latency + box * 3 * 8 * outside / bandwidth) if overlapped > 1 else 0.0
    membrane_halo = math.ceil(cells / p) * per_membrane
    # One plane of the three velocity components for the fluid stencils, four times per fluid step, to each
    # neighbour across the largest face of the local block.
    local = [n / q for q, n in zip(split, dims)] + list(dims[len(split):])
    face = max(local_cells / l for l, q in zip(local, split) if q > 1) if p > 1 else 0.0
    neighbours = 2 * sum(1 for q in split if q > 1)
    fluid_halo = 4 * neighbours * message(face * 3 * 8, latency, bandwidth) if p > 1 else 0.0
    halos = evals * (membrane_halo + fluid_halo)
    # Four Helmholtz/Poisson solves per fluid step, two transforms each: one all-to-all among all processes per
    # slab transform (transposed output and input), one among each split axis's processes for pencils.
    local_bytes = local_cells * 8
    transform = sum(all_to_all(q, local_bytes, latency, bandwidth) for q in split)
    ffts = evals * 4 * 2 * transform
    reductions = evals * 3 * max(1, math.ceil(math.log2(p))) * latency if p > 1 else 0.0
    total = compute + halos + ffts + reductions
    return {"total": total, "compute": compute, "halos": halos, "ffts": ffts, "reductions": reductions}


def table(title, rows):
    print(f"\n{title}")
    print("| processes | layout | grid per process | cells per process | step (s) | compute | halos | FFT transposes"
          " | reductions | efficiency |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for r in rows:
        print(f"| {r['p']:,} | {r['layout']} | {r['local']:,.0f} | {r['cells']:g} | {r['total']:.4f} | "
              f"{r['compute']:.4f} | {r['halos']:.4f} | {r['ffts']:.4f} | {r['reductions']:.5f} | "
              f"{100 * r['eff']:.0f} % |")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run_dir", metavar="RUN_DIR")
    parser.add_argument("--latency", type=float, default=2e-6, help="seconds per message (default 2e-6)")
    parser.add_argument("--bandwidth", type=float, default=3e9,
                        help="bytes per second per process (default 3e9: a 100 Gb/s link shared by 4 processes)")
    args = parser.parse_args()
    rates = measured_rates(args.run_dir)
    f, c, s, fl, i, r = rates["profile"]
    print(f"measured (one process, one thread, the paper's channel): {rates['evals']:.2f} evaluations per step; "
          f"ms per step: forces {1e3 * f:.1f}, contact {1e3 * c:.1f}, spreading {1e3 * s:.1f}, fluid {1e3 * fl:.1f}, "
          f"interpolation {1e3 * i:.1f}, the rest {1e3 * r:.1f}")
    print(f"rates: {rates['node'] * 1e9:.1f} ns per membrane node and {rates['cell'] * 1e9:.1f} ns per grid cell "
          f"per evaluation; {rates['rest'] * 1e9:.2f} ns per unknown per step")
    print(f"network: latency {args.latency:g} s, bandwidth {args.bandwidth:g} B/s per process")
    big = (8 * PAPER_GRID[0], 4 * PAPER_GRID[1], 4 * PAPER_GRID[2])
    big_cells = 1024
    for layout in ("slab", "pencil"):
        rows, base = [], None
        for p in (32, 64, 128, 256, 512, 1024):
            t = step_time(rates, big, big_cells, p, layout, args.latency, args.bandwidth)
            if t is None:
                print(f"\nstrong, {layout}s: {p} processes exceed the {max(big)} planes of the longest axis")
                continue
            base = base or (p, t["total"])
            t.update(p=p, layout=layout, local=math.prod(big) / p, cells=math.ceil(big_cells / p),
                     eff=base[1] * base[0] / (t["total"] * p))
            rows.append(t)
        table(f"Strong scaling, 1,024-cell channel {big[0]} x {big[1]} x {big[2]}, {layout}s", rows)
    for layout in ("slab", "pencil"):
        rows, base = [], None
        for p in (32, 64, 128, 256, 512, 1024):
            copies = p // 32
            ax = 1
            while ax * ax * 2 <= copies:
                ax *= 2
            cx, cy = (ax, copies // ax)
            grid = (PAPER_GRID[0] * cx, PAPER_GRID[1] * cy, PAPER_GRID[2])
            t = step_time(rates, grid, p, p, layout, args.latency, args.bandwidth)
            if t is None:
                print(f"\nweak, {layout}s: {p} processes exceed the {max(grid)} planes of the longest axis")
                continue
            base = base or t["total"]
            t.update(p=p, layout=layout, local=math.prod(grid) / p, cells=1, eff=base / t["total"])
            rows.append(t)
        table(f"Weak scaling, one cell and 1/32 of the duct per process, {layout}s", rows)


if __name__ == "__main__":
    main()
