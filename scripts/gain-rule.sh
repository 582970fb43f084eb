#!/usr/bin/env bash
# The gain rule of issue 22, fitted and checked on a tuned matrix run (key
# `tune`, e.g. matrices/tuned.toml): per method and integrator, one of
#   gain x h = c  (fixed step; a rate gain: lambda, alpha, omega; a time
#                 scale gain, dt: gain / h = c)
#   gain = c      (the same at every step or tolerance)
# whichever scatters the optima less (the standard deviation of log c over
# the problems used for the fit; adaptive integrators: gain = c only).
# For each problem, method, integrator and level of error against the
# reference, the tuned optimum is the cheapest case of the tuned curve (any
# gain, any step or tolerance) that reaches the level (among equal costs,
# the one with the smaller error: at a fixed step every gain costs the same
# RHS evaluations). c is the geometric
# mean of the optima's gain x h (or gain) over the OTHER problems (leave one
# problem out; the form is chosen on them too), and the rule's prediction
# for the left-out problem is, at each step or tolerance, the gain of the
# tuned grid nearest (in log) to c / h (or c); its cost is the cheapest of
# those cases that reaches the level.
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

def product(c, form):  # what the rule holds constant: form "h" (gain x h, or gain / h) or "const"
    if form == "const" or not c["fixed"]:
        return c["gain"]
    return c["gain"] / c["size"] if c["gain_name"] in TIME_SCALE else c["gain"] * c["size"]

def fit(optima, fixed):
    """The form whose log c scatters least over `optima`, and c (geometric mean)."""
    best = None
    for form in (["h", "const"] if fixed else ["const"]):
        logs = [math.log(product(o, form)) for o in optima]
        mean = sum(logs) / len(logs)
        spread = math.sqrt(sum((x - mean) ** 2 for x in logs) / len(logs))
        if best is None or spread < best[2] - 1e-12:
            best = (form, math.exp(mean), spread)
    return best

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
    fixed = cs[0]["fixed"]
    form, c_all, spread = fit(list(optimum.values()), fixed)
    values = [product(o, form) for o in optimum.values()]
    fits.append((method, integ, cs[0]["gain_name"], fixed, form, c_all, spread, min(values), max(values), len(values)))
    for (p, level), best in sorted(optimum.items()):
        others = [o for (q, _), o in optimum.items() if q != p]
        if not others:
            continue  # one problem only: nothing to fit from
        form_p, c_rule, _ = fit(others, fixed)
        def rule_gain(size):
            g = c_rule
            if form_p == "h":
                g = c_rule * size if cs[0]["gain_name"] in TIME_SCALE else c_rule / size
            return min(grid, key=lambda x: abs(math.log(x) - math.log(g)))
        picks = [c for c in cs if c["problem"] == p and c["gain"] == rule_gain(c["size"])]
        ruled = cheapest(picks, level)
        ratio = ruled["rhs"] / best["rhs"] if ruled else math.inf
        wall_ratio = ruled["wall"] / best["wall"] if ruled else math.inf
        rows.append((p, method, integ, level, best, (form_p, c_rule), ruled, ratio, wall_ratio))

def rule_text(name, form):
    if form == "const":
        return "%s = c" % name
    return "%s / h = c" % name if name in TIME_SCALE else "%s h = c" % name

print("| method | integrator | rule (less scattered form) | c (all problems) | scatter of log c | optima's range | optima |")
print("|---|---|---|---|---|---|---|")
for method, integ, name, fixed, form, c, spread, lo, hi, n in fits:
    note = ""
    if form == "h" and integ == "rk4" and name not in TIME_SCALE:
        note = " (RK4 linear theory: stable below 2.785, fastest damping 1.596)"
    print("| %s | %s | %s | %.3g%s | %.2f | %.3g .. %.3g | %d |" % (method, integ, rule_text(name, form), c, note,
                                                                   spread, lo, hi, n))
print()
print("| problem | method | integrator | error <= | optimum (gain, setting) | rhs | rule (fitted on the others) | rule's case | rhs | rule / optimum (rhs) | (wall) |")
print("|---|---|---|---|---|---|---|---|---|---|---|")
ok = 0
for p, method, integ, level, best, (form_p, c_rule), ruled, ratio, wall_ratio in rows:
    ok += ratio <= 1.5
    bs = "%s=%.3g, %s=%.3g" % (best["gain_name"], best["gain"], "h" if best["fixed"] else "tol", best["size"])
    rs = ("%s=%.3g, %s=%.3g" % (ruled["gain_name"], ruled["gain"], "h" if ruled["fixed"] else "tol", ruled["size"])
          if ruled else "does not reach")
    print("| %s | %s | %s | %g | %s | %d | %s, c = %.3g | %s | %s | %s | %s |" % (
        p, method, integ, level, bs, best["rhs"], rule_text(best["gain_name"], form_p), c_rule, rs, "%d" % ruled["rhs"] if ruled else "",
        "%.2f" % ratio if ratio < math.inf else "inf", "%.2f" % wall_ratio if wall_ratio < math.inf else "inf"))
print()
print("rule within 1.5x of the tuned optimum (RHS evaluations, leave one problem out): %d of %d cases (%.0f %%)" % (
    ok, len(rows), 100.0 * ok / len(rows) if rows else 0))
PY
