#!/usr/bin/env bash
# The gain rule of issue 22, fitted and checked on a tuned matrix run (key
# `tune`, e.g. matrices/tuned.toml): per method and integrator,
#   fixed step: gain x h = c  (a rate gain: lambda, alpha, omega; a time
#               scale gain, dt: gain / h = c)
#   adaptive:   gain = c      (the same at every tolerance)
# For each problem, method, integrator and level of error against the
# reference, the tuned optimum is the cheapest case of the tuned curve (any
# gain, any step or tolerance) that reaches the level (among equal costs,
# the one with the smaller error: at a fixed step every gain costs the same
# RHS evaluations). c is the geometric
# mean of the optima's gain x h (or gain) over the OTHER problems (leave one
# problem out), and the rule's prediction for the left-out problem is, at
# each step or tolerance, the gain of the tuned grid nearest (in log) to c / h
# (or c); its cost is the cheapest of those cases that reaches the level.
# Cost: RHS evaluations (noise-free), with the wall-time ratio beside it.
# Prints the cases, c per method and integrator (with RK4's linear theory
# for a rate gain: stable for gain x h < 2.785, fastest damping at 1.596),
# and the share of cases where the rule costs within 1.5x of the optimum.
#   usage: bash scripts/gain-rule.sh RESULTS_DIR [LEVELS]
set -euo pipefail
dir=${1:?usage: scripts/gain-rule.sh RESULTS_DIR [LEVELS]}
levels=${2:-1e-4 1e-6 1e-8}
wp=$dir/work_precision.csv
[ -f "$wp" ] || { echo "gain-rule: no $wp (not a matrix results folder with a report)" >&2; exit 2; }
command -v python3 >/dev/null || { echo "gain-rule: needs python3 (apt-get install python3)" >&2; exit 2; }
python3 - "$wp" "$levels" <<'PY'
import csv, math, sys
from collections import defaultdict

path, levels_text = sys.argv[1], sys.argv[2]
try:
    levels = [float(x) for x in levels_text.split()]
    assert levels and all(l > 0 for l in levels)
except (ValueError, AssertionError):
    sys.exit("gain-rule: levels '%s': expected numbers > 0" % levels_text)
TIME_SCALE = {"dt"}  # gains that are time scales (ParamRole::kTimeScale)

cases = []  # tuned, finished cases with a reference error
with open(path, newline="") as f:
    for r in csv.DictReader(f):
        if not r["curve"].endswith(" tuned") or r["status"] != "ok" or not r["ref_error"] or not r["params"]:
            continue
        name, value = r["params"].split(";")[0].split("=")
        fixed = r["setting"].startswith("step=")
        cases.append(dict(problem=r["problem"], method=r["method"], integrator=r["integrator"], gain_name=name,
                          gain=float(value), fixed=fixed, size=float(r["step"] if fixed else r["rtol"]),
                          error=float(r["ref_error"]), rhs=float(r["rhs_evals"] or "nan"),
                          wall=float(r["wall_median_s"] or "nan")))
if not cases:
    sys.exit("gain-rule: no finished tuned case with a reference error in %s (run a matrix with the key tune)" % path)

def product(c):  # what the rule holds constant
    if not c["fixed"]:
        return c["gain"]
    return c["gain"] / c["size"] if c["gain_name"] in TIME_SCALE else c["gain"] * c["size"]

def cheapest(cs, level):
    reach = [c for c in cs if c["error"] <= level and not math.isnan(c["rhs"])]
    # Equal RHS counts (fixed step: every gain at one step) go to the smaller error.
    return min(reach, key=lambda c: (c["rhs"], c["error"])) if reach else None

groups = defaultdict(list)
for c in cases:
    groups[(c["method"], c["integrator"])].append(c)

rows, fits = [], []
for (method, integ), cs in sorted(groups.items()):
    grid = sorted({c["gain"] for c in cs})
    problems = sorted({c["problem"] for c in cs})
    optimum = {}
    for p in problems:
        for level in levels:
            best = cheapest([c for c in cs if c["problem"] == p], level)
            if best:
                optimum[(p, level)] = best
    if not optimum:
        continue
    all_logs = [math.log(product(o)) for o in optimum.values()]
    fits.append((method, integ, cs[0]["gain_name"], cs[0]["fixed"], math.exp(sum(all_logs) / len(all_logs)),
                 min(map(product, optimum.values())), max(map(product, optimum.values())), len(all_logs)))
    for (p, level), best in sorted(optimum.items()):
        others = [math.log(product(o)) for (q, _), o in optimum.items() if q != p]
        if not others:
            continue  # one problem only: nothing to fit from
        c_rule = math.exp(sum(others) / len(others))
        def rule_gain(size):
            fixed = cs[0]["fixed"]
            g = c_rule if not fixed else (c_rule * size if cs[0]["gain_name"] in TIME_SCALE else c_rule / size)
            return min(grid, key=lambda x: abs(math.log(x) - math.log(g)))
        picks = [c for c in cs if c["problem"] == p and c["gain"] == rule_gain(c["size"])]
        ruled = cheapest(picks, level)
        ratio = ruled["rhs"] / best["rhs"] if ruled else math.inf
        wall_ratio = ruled["wall"] / best["wall"] if ruled else math.inf
        rows.append((p, method, integ, level, best, c_rule, ruled, ratio, wall_ratio))

print("| method | integrator | rule | c (all problems) | optima's range | optima |")
print("|---|---|---|---|---|---|")
for method, integ, name, fixed, c, lo, hi, n in fits:
    rule = ("%s / h = c" % name if name in TIME_SCALE else "%s h = c" % name) if fixed else "%s = c" % name
    note = ""
    if fixed and integ == "rk4" and name not in TIME_SCALE:
        note = " (RK4 linear theory: stable below 2.785, fastest damping 1.596)"
    print("| %s | %s | %s | %.3g%s | %.3g .. %.3g | %d |" % (method, integ, rule, c, note, lo, hi, n))
print()
print("| problem | method | integrator | error <= | optimum (gain, setting) | rhs | rule c (others) | rule's case | rhs | rule / optimum (rhs) | (wall) |")
print("|---|---|---|---|---|---|---|---|---|---|---|")
ok = 0
for p, method, integ, level, best, c_rule, ruled, ratio, wall_ratio in rows:
    ok += ratio <= 1.5
    bs = "%s=%.3g, %s=%.3g" % (best["gain_name"], best["gain"], "h" if best["fixed"] else "tol", best["size"])
    rs = ("%s=%.3g, %s=%.3g" % (ruled["gain_name"], ruled["gain"], "h" if ruled["fixed"] else "tol", ruled["size"])
          if ruled else "does not reach")
    print("| %s | %s | %s | %g | %s | %d | %.3g | %s | %s | %s | %s |" % (
        p, method, integ, level, bs, best["rhs"], c_rule, rs, "%d" % ruled["rhs"] if ruled else "",
        "%.2f" % ratio if ratio < math.inf else "inf", "%.2f" % wall_ratio if wall_ratio < math.inf else "inf"))
print()
print("rule within 1.5x of the tuned optimum (RHS evaluations, leave one problem out): %d of %d cases (%.0f %%)" % (
    ok, len(rows), 100.0 * ok / len(rows) if rows else 0))
PY
