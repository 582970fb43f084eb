#!/usr/bin/env python3
"""How the cost of n-four-bar (IFToMM A02) grows with N, band against dense.

Two measurements, each from `cstab run` and the harness's own wall time
(integration alone; the median of REPEATS runs):

  per step   RK4 at a fixed step h = 1e-3 from the start; the number of steps
             is chosen per case so that each run takes a fraction of a second
             (the dense path at N = 320 runs a few steps only). Prints the wall
             time per step.
  accuracy   rk8pd over the benchmark's 20 s, tolerances 1e-5 .. 1e-11; for
             each N the cheapest run whose error against the reference
             (all canonical coordinates at t = 20) is <= TARGET.

For each method and KKT solver (kkt=0 band, kkt=1 dense) it fits the exponent
p of wall = c N^p by least squares on log-log over the N measured, and prints
it. Results go to OUT (default results/scaling): per-step.csv, accuracy.csv.

Usage: python3 scripts/scaling.py [--cstab PATH] [--out DIR] [--repeats R]
         [--n 5,10,...] [--methods m1,m2] [--target E] [--dense-max-n N]
         [--skip-accuracy] [--skip-per-step]
"""
import argparse
import csv
import math
import os
import statistics
import subprocess
import sys
import tempfile

TOLS = ["1e-5", "1e-6", "1e-7", "1e-8", "1e-9", "1e-10", "1e-11"]
H = 1e-3


def run(cstab, args, n, method, kkt, extra):
    with tempfile.TemporaryDirectory() as out:
        cmd = [cstab, "run", "--problem", "n-four-bar", "--problem-param", f"N={n}", "--method", method, "--param",
               f"kkt={kkt}", "--no-series", "--out", out] + extra
        p = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        if p.returncode != 0:
            sys.exit(f"scaling.py: {' '.join(cmd)} failed ({p.returncode}): {p.stderr.strip()}")
        with open(os.path.join(out, "summary.csv")) as f:
            return next(csv.DictReader(f))


def median_run(cstab, args, n, method, kkt, extra):
    rows = [run(cstab, args, n, method, kkt, extra) for _ in range(args.repeats)]
    walls = sorted(float(r["wall_seconds"]) for r in rows)
    row = rows[0]
    row["wall_seconds"] = statistics.median(walls)
    return row


def fit(points):
    """Least-squares slope of log(wall) on log(N)."""
    pts = [(math.log(n), math.log(w)) for n, w in points if w > 0]
    if len(pts) < 2:
        return float("nan")
    mx = sum(x for x, _ in pts) / len(pts)
    my = sum(y for _, y in pts) / len(pts)
    sxx = sum((x - mx)**2 for x, _ in pts)
    return sum((x - mx) * (y - my) for x, y in pts) / sxx


def steps_for(n, kkt):
    size = 4 * n + 3  # KKT rows: 2(N+1) coordinates, 2N+1 constraints
    if kkt == 0:
        return 2000
    # dense LU ~ (2/3) size^3 flops, four factorizations per RK4 step
    return max(4, min(2000, int(2e9 / (size**3))))


def cases(args, methods, dense_max_n):
    """(method, kkt, N) in the order measured; the dense path up to dense_max_n."""
    for method in methods:
        for kkt in (0, 1):
            for n in args.n:
                if kkt == 0 or n <= dense_max_n:
                    yield method, kkt, n


def per_step(args, methods):
    rows = []
    print("per step: RK4, h = 1e-3, median of", args.repeats)
    print(f"{'method':<20} {'kkt':<6} {'N':>5} {'steps':>6} {'wall_s':>10} {'us/step':>10}")
    for method, kkt, n in cases(args, methods, args.dense_max_n):
        steps = steps_for(n, kkt)
        r = median_run(args.cstab, args, n, method, kkt,
                       ["--integrator", "rk4", "--step", str(H), "--t-end", repr(steps * H)])
        if r["status"] != "ok":
            print(f"{method:<20} {kkt:<6} {n:>5} status {r['status']}")
            continue
        done = int(r["steps"])
        us = 1e6 * r["wall_seconds"] / done
        name = "band" if kkt == 0 else "dense"
        print(f"{method:<20} {name:<6} {n:>5} {done:>6} {r['wall_seconds']:>10.4g} {us:>10.4g}")
        rows.append((method, name, n, done, r["wall_seconds"], us))
    return rows


def accuracy(args, methods):
    rows = []
    print(f"\nat equal accuracy: rk8pd, t_end = 20, cheapest run with ref_error <= {args.target:g}")
    print(f"{'method':<20} {'kkt':<6} {'N':>5} {'tol':>7} {'steps':>6} {'ref_error':>10} {'wall_s':>10}")
    for method, kkt, n in cases(args, methods, args.dense_accuracy_max_n):
        best = None
        for tol in TOLS:
            r = median_run(args.cstab, args, n, method, kkt,
                           ["--integrator", "rk8pd", "--rtol", tol, "--atol", tol, "--t-end", "20", "--max-steps",
                            "3e5"])
            if r["status"] == "ok" and r["ref_error"] and float(r["ref_error"]) <= args.target:
                best = (tol, r)
                break  # tolerances ascend in cost: the first that reaches is the cheapest
        name = "band" if kkt == 0 else "dense"
        if best is None:
            print(f"{method:<20} {name:<6} {n:>5} not reached at tol {TOLS[-1]}")
            continue
        tol, r = best
        print(f"{method:<20} {name:<6} {n:>5} {tol:>7} {r['steps']:>6} {float(r['ref_error']):>10.3g} "
              f"{r['wall_seconds']:>10.4g}")
        rows.append((method, name, n, tol, int(r["steps"]), float(r["ref_error"]), r["wall_seconds"]))
    return rows


def print_fits(title, rows, wall_index):
    print(f"\nexponent p of {title} = c N^p (least squares on log-log)")
    keys = sorted({(r[0], r[1]) for r in rows})
    for key in keys:
        pts = [(r[2], r[wall_index]) for r in rows if (r[0], r[1]) == key]
        ns = ",".join(str(p[0]) for p in pts)
        print(f"  {key[0]:<20} {key[1]:<6} p = {fit(pts):.2f}  (N = {ns})")


def write_csv(path, header, rows):
    tmp = path + ".tmp"
    with open(tmp, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        w.writerows(rows)
    os.replace(tmp, path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    here = os.path.dirname(os.path.abspath(__file__))
    ap.add_argument("--cstab", default=os.path.join(here, "..", "build", "release", "cli", "cstab"))
    ap.add_argument("--out", default=os.path.join(here, "..", "results", "scaling"))
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--n", default="5,10,20,40,80,160,320")
    ap.add_argument("--methods", default="projection,post-stabilization,baumgarte")
    ap.add_argument("--target", type=float, default=1e-3)
    ap.add_argument("--dense-max-n", type=int, default=320)
    ap.add_argument("--dense-accuracy-max-n", type=int, default=80)
    ap.add_argument("--skip-accuracy", action="store_true")
    ap.add_argument("--skip-per-step", action="store_true")
    args = ap.parse_args()
    try:
        args.n = [int(x) for x in args.n.split(",")]
    except ValueError:
        print(f"scaling.py: --n: '{args.n}' is not a comma-separated list of integers", file=sys.stderr)
        sys.exit(2)
    if args.repeats < 1 or not all(1 <= n <= 1000 for n in args.n) or not args.target > 0:
        print("scaling.py: --repeats >= 1, --n values in [1, 1000] and --target > 0", file=sys.stderr)
        sys.exit(2)
    if not os.access(args.cstab, os.X_OK):
        print(f"scaling.py: no cstab at {args.cstab} (build first: bash scripts/build.sh)", file=sys.stderr)
        sys.exit(2)
    methods = args.methods.split(",")
    os.makedirs(args.out, exist_ok=True)
    if not args.skip_per_step:
        steps = per_step(args, methods)
        write_csv(os.path.join(args.out, "per-step.csv"),
                  ["method", "kkt", "N", "steps", "wall_seconds", "us_per_step"], steps)
        print_fits("wall per step", steps, 5)
    if not args.skip_accuracy:
        acc = accuracy(args, methods)
        write_csv(os.path.join(args.out, "accuracy.csv"),
                  ["method", "kkt", "N", "tol", "steps", "ref_error", "wall_seconds"], acc)
        print_fits(f"wall at ref_error <= {args.target:g}", acc, 6)


if __name__ == "__main__":
    main()
