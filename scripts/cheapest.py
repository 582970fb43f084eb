#!/usr/bin/env python3
"""Per problem variant and method/integrator, the cheapest setting of a
results folder whose error against the reference reaches each target (the
median wall time of its repeats); used for docs/measurements.md's stiffness
tables.
  python3 scripts/cheapest.py RESULTS_DIR TARGET [TARGET ...]
"""
import csv
import statistics
import sys
from collections import defaultdict


def main(argv):
    if len(argv) < 3:
        sys.exit("usage: cheapest.py RESULTS_DIR TARGET [TARGET ...]")
    try:
        targets = [float(t) for t in argv[2:]]
    except ValueError as e:
        print(f"cheapest.py: {e}", file=sys.stderr)
        sys.exit(2)
    try:
        with open(argv[1] + "/summary.csv", newline="") as f:
            rows = list(csv.DictReader(f))
    except OSError as e:
        print(f"cheapest.py: {e}", file=sys.stderr)
        sys.exit(2)
    runs = defaultdict(list)
    for r in rows:
        if r["status"] == "ok" and r["ref_error"]:
            setting = f"rtol={r['rtol']}" if r["rtol"] else f"h={r['step']}"
            runs[(r["problem"], r["problem_params"], r["method"], r["integrator"], setting)].append(r)
    for target in targets:
        print(f"# error <= {target:g}")
        best = {}
        for (problem, variant, method, integrator, setting), rs in runs.items():
            error = float(rs[0]["ref_error"])
            if error > target:
                continue
            wall = statistics.median(float(r["wall_seconds"]) for r in rs)
            key = (problem, variant, method, integrator)
            if key not in best or wall < best[key][0]:
                best[key] = (wall, error, rs[0]["steps"], setting)
        for variant in sorted({k[:2] for k in best}):
            print(f"{variant[0]} {variant[1]}:")
            for key, (wall, error, steps, setting) in sorted(
                    ((k, v) for k, v in best.items() if k[:2] == variant), key=lambda kv: kv[1][0]):
                print(f"  {key[2]}/{key[3]} {setting}: {wall * 1e3:.1f} ms, error {error:.1e}, {steps} steps")


if __name__ == "__main__":
    main(sys.argv)
