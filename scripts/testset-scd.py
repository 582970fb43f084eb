#!/usr/bin/env python3
"""The IVP Test Set's own score of a fekete run at t = 1000.

cstab's `ref_scd` column is -log10 max |y - y_ref| / (1 + |y_ref|) over the
canonical state. The Test Set's report.f scores fekete by
scd = -log10 max_i |y_i - y_ref,i| / |y_ref,i| over the 60 positions only.
This script reads a run's series (RUN/series.csv or series.csv.gz, written
by `cstab run --problem fekete --t-end 1000 --ref-time 1000 --out RUN`),
takes its row at t = 1000 and prints both scores.

Usage: scripts/testset-scd.py RUN [RUN ...]
"""
import csv
import gzip
import math
import os
import re
import sys

HERE = os.path.dirname(os.path.abspath(__file__))


def published_positions():
    # The values in problems/fekete/fekete.cpp, test_set_solution().
    src = open(os.path.join(HERE, "..", "problems", "fekete", "fekete.cpp")).read()
    body = src[src.index("static const std::vector<double> y = {"):]
    body = body[: body.index("};")]
    values = [float(v) for v in re.findall(r"-?\d\.\d+e[+-]\d+", body)]
    if len(values) != 120:
        sys.exit(f"testset-scd: expected 120 published values, found {len(values)}")
    return values[:60]


def last_row(run):
    for name in ("series.csv", "series.csv.gz"):
        path = os.path.join(run, name)
        if os.path.exists(path):
            opener = gzip.open if name.endswith(".gz") else open
            with opener(path, "rt") as f:
                rows = list(csv.reader(f))
            return rows[0], rows[-1]
    sys.exit(f"testset-scd: {run}: no series.csv or series.csv.gz")


def main(runs):
    if not runs:
        sys.exit(__doc__)
    ref = published_positions()
    names = [f"{a}_{i}" for i in range(1, 21) for a in "xyz"]
    for run in runs:
        head, row = last_row(run)
        missing = [n for n in names + ["t"] if n not in head]
        if missing:
            sys.exit(f"testset-scd: {run}: not a fekete N = 20 series (missing {missing[0]})")
        t = float(row[head.index("t")])
        if abs(t - 1000) > 1e-9:
            sys.exit(f"testset-scd: {run}: the series ends at t = {t}, not 1000")
        y = [float(row[head.index(n)]) for n in names]
        rel = max(abs(a - b) / abs(b) for a, b in zip(y, ref))
        mixed = max(abs(a - b) / (1 + abs(b)) for a, b in zip(y, ref))
        score = lambda e: 16.0 if e == 0 else -math.log10(e)
        print(f"{run}: Test Set scd {score(rel):.2f} (positions, relative), "
              f"cstab-style {score(mixed):.2f} (positions, 1 + |y_ref|)")


if __name__ == "__main__":
    main(sys.argv[1:])
