#!/usr/bin/env bash
# Compares the summary.csv of two results folders case by case, ignoring the
# timing columns (wall_seconds, observe_seconds, and any *_seconds column):
#   bash scripts/compare-results.sh BEFORE_DIR AFTER_DIR
# Prints how many rows are identical, lists every other difference (column,
# both values, relative difference for numbers), and exits 1 if any.
# Only each case's first run (repeat 0) is compared: how many timing repeats
# a case gets depends on its wall time (repeat_if_under), and a repeat's
# numbers other than its timings are those of the first run.
set -euo pipefail
[[ $# -eq 2 ]] || { echo "usage: $0 BEFORE_DIR AFTER_DIR" >&2; exit 2; }
command -v python3 >/dev/null || { echo "compare-results: needs python3 (apt-get install python3)" >&2; exit 2; }
python3 - "$1/summary.csv" "$2/summary.csv" <<'PY'
import csv, sys
def load(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    key = lambda r: (r["problem"], r["method"], r["formulation"], r["integrator"], r["params"], r["step"],
                     r["rtol"], r["atol"], r["t_end"], r.get("sweep", ""), r.get("repeat", ""), r.get("perturb", ""))
    out = {}
    for r in rows:
        if r.get("repeat", "0") == "0":
            out.setdefault(key(r), r)
    return out, (rows[0].keys() if rows else [])
before, cols_b = load(sys.argv[1])
after, cols_a = load(sys.argv[2])
timing = lambda c: c.endswith("_seconds") or c in ("case_id",)
diffs = 0
same = 0
for k in sorted(set(before) | set(after)):
    if k not in before or k not in after:
        print("only in", "after" if k not in before else "before", ":", k); diffs += 1; continue
    a, b = before[k], after[k]
    row_diffs = []
    for c in sorted(set(a) | set(b)):
        if timing(c): continue
        va, vb = a.get(c, "<missing>"), b.get(c, "<missing>")
        if va == vb: continue
        try:
            x, y = float(va), float(vb)
            rel = abs(x - y) / max(abs(x), abs(y), 1e-300)
            row_diffs.append(f"{c}: {va} -> {vb} (rel {rel:.1e})")
        except ValueError:
            row_diffs.append(f"{c}: {va!r} -> {vb!r}")
    if row_diffs:
        diffs += 1
        print(" / ".join(k[:5]), "|", "; ".join(row_diffs))
    else:
        same += 1
print(f"{same} rows identical (timing columns ignored), {diffs} differ, of {len(set(before) | set(after))}")
sys.exit(1 if diffs else 0)
PY
