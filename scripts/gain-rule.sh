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
# Two fits of c (and of the form) on the other problems are compared:
#   gmean  the geometric mean of their optima (above);
#   cost   the form and c whose rule costs least on them: the mean over
#          their cases of log(rule's cost / optimum's cost), a rule that does
#          not reach a level counting as 100x; c is tried at every gain x h
#          (or gain) of the tuned grid. An optimum's gain says little where
#          the cost is flat in the gain, and one far-off optimum drags the
#          geometric mean; this fits what the rule is judged by. (Wider
#          families, gain = c s^p with s the step or the tolerance and p in
#          {0, +-1/4, ..., +-1}, fit the other problems better and predict
#          the left-out one worse: on matrices/gain-rule.toml 94 of 125
#          cases against 102; docs/measurements.md.)
# GAIN_RULE_FIT=gmean|cost (default cost) picks the fit whose table is printed;
# the share within 1.5x is printed for both.
# GAIN_RULE_RATES=FILE adds a third form scaled by a property of the
# problem known before any run: gain = c r, r the problem's characteristic
# rate (1/s) from FILE, the CSV of bench/problem_rates.cpp
# (`build/release/bench/cstab-problem-rates > FILE`), column
# GAIN_RULE_RATE (default rate_median: the spectral radius of the
# unstabilized index-1 ODE's Jacobian, median along the trajectory).
# Also printed: the best share any c of the allowed forms reaches when
# fitted on every problem, the predicted one included, per method and
# integrator: no leave-one-out fit of the same forms can do better.
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

def die(message):  # bad input: the message, exit 2
    print(message, file=sys.stderr)
    sys.exit(2)
from collections import defaultdict

path, levels_text = sys.argv[1], sys.argv[2]
try:
    levels = [float(x) for x in levels_text.split()]
    assert levels and all(l > 0 for l in levels)
except (ValueError, AssertionError):
    die("gain-rule: levels '%s': expected numbers > 0" % levels_text)
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
    die("gain-rule: no finished tuned case with a reference error in %s (run a matrix with the key tune)" % path)

import os
RATES = {}  # problem -> its characteristic rate (GAIN_RULE_RATES)
if os.environ.get("GAIN_RULE_RATES"):
    rates_path, column = os.environ["GAIN_RULE_RATES"], os.environ.get("GAIN_RULE_RATE", "rate_median")
    try:
        with open(rates_path, newline="") as f:
            for r in csv.DictReader(f):
                RATES[r["problem"]] = float(r[column])
    except (OSError, KeyError, ValueError, TypeError) as e:
        die("gain-rule: GAIN_RULE_RATES %s: not a cstab-problem-rates CSV with a column %s (%s)" % (
            rates_path, column, e))
    missing = sorted({c["problem"] for c in cases} - {p for p, r in RATES.items() if r > 0 and math.isfinite(r)})
    if missing:
        die("gain-rule: GAIN_RULE_RATES %s: no rate > 0 for %s" % (rates_path, ", ".join(missing)))
FORMS_FIXED = ["h", "const"] + (["rate"] if RATES else [])
FORMS_ADAPTIVE = ["const"] + (["rate"] if RATES else [])

# A rule's form is the power p in gain = c s^p, s the step h (fixed step) or
# the tolerance (adaptive): "const" is p = 0, "h" is gain x h = c (p = -1; a
# time scale gain: gain / h = c, p = 1), a number is p itself; "rate" is
# gain = c r with r the problem's characteristic rate (a time scale gain:
# gain = c / r).

def power(form, gain_name):
    if form in ("const", "rate"):
        return 0
    if form == "h":
        return 1 if gain_name in TIME_SCALE else -1
    return form

def rate_factor(form, problem, gain_name):  # r (or 1 / r) in the "rate" form, else 1
    if form != "rate":
        return 1.0
    return 1 / RATES[problem] if gain_name in TIME_SCALE else RATES[problem]

def product(c, form):  # what the rule holds constant: gain / (s^p r)
    if form == "h" and not c["fixed"]:
        return c["gain"]
    return c["gain"] / c["size"] ** power(form, c["gain_name"]) / rate_factor(form, c["problem"], c["gain_name"])

def fit(optima, fixed):
    """The form whose log c scatters least over `optima`, and c (geometric mean)."""
    best = None
    for form in (FORMS_FIXED if fixed else FORMS_ADAPTIVE):
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

FIT = __import__("os").environ.get("GAIN_RULE_FIT", "cost")
if FIT not in ("cost", "gmean"):
    die("gain-rule: GAIN_RULE_FIT '%s': expected cost or gmean" % FIT)
CAP = 100.0  # a rule that does not reach a level counts as this many times the optimum's cost

def rule_case(cs, p, level, form, c, grid):
    """The rule's cheapest case on problem p that reaches level (None if none does)."""
    def rule_gain(size):
        g = c * size ** power(form, cs[0]["gain_name"]) * rate_factor(form, p, cs[0]["gain_name"])
        return min(grid, key=lambda x: abs(math.log(x) - math.log(g)))
    return cheapest([x for x in cs if x["problem"] == p and x["gain"] == rule_gain(x["size"])], level)

def candidates(cs, fixed):
    """Every (form, c) a fit tries: each allowed form, c at each case's value of the rule's product."""
    for form in (FORMS_FIXED if fixed else FORMS_ADAPTIVE):
        for c in sorted({product(x, form) for x in cs}):
            yield form, c

def fit_by_cost(cs, keys, optimum, fixed, grid):
    """The form (power of h or tol) and c whose rule costs least over the (problem, level) keys."""
    best = None
    for form, c in candidates(cs, fixed):
        loss = 0.0
        for (p, level) in keys:
            ruled = rule_case(cs, p, level, form, c, grid)
            loss += math.log(min(ruled["rhs"] / optimum[(p, level)]["rhs"], CAP) if ruled else CAP)
        loss /= len(keys)
        if best is None or loss < best[2] - 1e-12:
            best = (form, c, loss)
    return best

def best_in_hindsight(cs, optimum, fixed, grid):
    """The most (problem, level) keys within 1.5x that one form and c reach, fitted on all of them."""
    best = (0, None, None)
    for form, c in candidates(cs, fixed):
        n = 0
        for (p, level), opt in optimum.items():
            ruled = rule_case(cs, p, level, form, c, grid)
            n += bool(ruled) and ruled["rhs"] / opt["rhs"] <= 1.5
        if n > best[0]:
            best = (n, form, c)
    return best

hindsight = {}  # (method, integrator) -> (cases within 1.5x, form, c), fitted on every problem
groups = defaultdict(list)
for c in cases:
    groups[(c["method"], c["integrator"])].append(c)

rows, fits = [], []
other_ok = {}  # the other fit's count of cases within 1.5x
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
    cform, c_cost, loss = fit_by_cost(cs, list(optimum), optimum, fixed, grid)
    if len({p for p, _ in optimum}) > 1:  # as the leave-one-out rows: a problem alone has nothing to fit from
        hindsight[(method, integ)] = best_in_hindsight(cs, optimum, fixed, grid)
    fits.append((method, integ, cs[0]["gain_name"], fixed, form, c_all, spread, min(values), max(values), len(values),
                 cform, c_cost, math.exp(loss)))
    fitted = {}  # left-out problem -> {fit: (form, c)}
    for p in problems:
        keys = [k for k in optimum if k[0] != p]
        if keys:  # one problem only: nothing to fit from
            fitted[p] = {"gmean": fit([optimum[k] for k in keys], fixed)[:2],
                         "cost": fit_by_cost(cs, keys, optimum, fixed, grid)[:2]}
    for (p, level), best in sorted(optimum.items()):
        if p not in fitted:
            continue
        for kind in ("gmean", "cost"):
            form_p, c_rule = fitted[p][kind]
            ruled = rule_case(cs, p, level, form_p, c_rule, grid)
            ratio = ruled["rhs"] / best["rhs"] if ruled else math.inf
            if kind != FIT:
                other_ok[kind] = other_ok.get(kind, 0) + (ratio <= 1.5)
                continue
            wall_ratio = ruled["wall"] / best["wall"] if ruled else math.inf
            rows.append((p, method, integ, level, best, (form_p, c_rule), ruled, ratio, wall_ratio))

def rule_text(name, form, fixed):
    if form == "rate":
        return "%s = c / r" % name if name in TIME_SCALE else "%s = c r" % name
    p = power(form, name)
    if p == 0:
        return "%s = c" % name
    if fixed and p == -1:
        return "%s h = c" % name
    if fixed and p == 1:
        return "%s / h = c" % name
    return "%s = c %s^%g" % (name, "h" if fixed else "tol", p)

print("| method | integrator | gmean: rule (less scattered form) | c (all problems) | scatter of log c | optima's range | optima | cost fit: rule | c | rule / optimum (geometric mean) |")
print("|---|---|---|---|---|---|---|---|---|---|")
for method, integ, name, fixed, form, c, spread, lo, hi, n, cform, c_cost, mean_ratio in fits:
    note = ""
    if form == "h" and integ == "rk4" and name not in TIME_SCALE:
        note = " (RK4 linear theory: stable below 2.785, fastest damping 1.596)"
    print("| %s | %s | %s | %.3g%s | %.2f | %.3g .. %.3g | %d | %s | %.3g | %.2f |" % (
        method, integ, rule_text(name, form, fixed), c, note, spread, lo, hi, n, rule_text(name, cform, fixed), c_cost,
        mean_ratio))
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
        p, method, integ, level, bs, best["rhs"], rule_text(best["gain_name"], form_p, best["fixed"]), c_rule, rs, "%d" % ruled["rhs"] if ruled else "",
        "%.2f" % ratio if ratio < math.inf else "inf", "%.2f" % wall_ratio if wall_ratio < math.inf else "inf"))
print()
def share(n):
    return "%d of %d cases (%.0f %%)" % (n, len(rows), 100.0 * n / len(rows) if rows else 0)
other = "gmean" if FIT == "cost" else "cost"
print("rule within 1.5x of the tuned optimum (RHS evaluations, leave one problem out), c fitted by %s: %s" % (
    FIT, share(ok)))
print("  (c fitted by %s instead: %s)" % (other, share(other_ok.get(other, 0))))
print()
print("The best any one c of the forms (%s; adaptive: %s) does, fitted on every problem, the predicted one included:" % (
    ", ".join(FORMS_FIXED), ", ".join(FORMS_ADAPTIVE)))
print("| method | integrator | rule | c | within 1.5x |")
print("|---|---|---|---|---|")
n_best = n_all = 0
for (method, integ), (n, form, c) in sorted(hindsight.items()):
    cs = groups[(method, integ)]
    keys = sum(1 for r in rows if r[1] == method and r[2] == integ)
    n_best, n_all = n_best + n, n_all + keys
    print("| %s | %s | %s | %.3g | %d of %d |" % (method, integ, rule_text(cs[0]["gain_name"], form, cs[0]["fixed"]) if form else "-",
                                             c if c else float("nan"), n, keys))
print("in hindsight: %d of %d cases (%.0f %%)" % (n_best, n_all, 100.0 * n_best / n_all if n_all else 0))
PY
