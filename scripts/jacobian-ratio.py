#!/usr/bin/env python3
"""The implicit integrators with the index-1 methods' AD Jacobian against the
same runs with difference quotients (CSTAB_JACOBIAN=dq), as ratios from one
sitting: for each case, REPEATS runs of each, alternating, and the medians of
the harness's own wall time (integration alone).

Usage: python3 scripts/jacobian-ratio.py [--cstab PATH] [--repeats N]
Prints one row per case: steps, right-hand sides and Jacobians of each, the
reference error of each, the median wall times and dq / ad.
"""
import argparse
import csv
import os
import statistics
import subprocess
import sys
import tempfile

# problem, method, params, integrator, tolerance
CASES = [
    ("car-axis", "baumgarte", [], "cvode-bdf", "1e-8"),
    ("flyball-governor", "none", [], "cvode-bdf", "1e-8"),
    ("andrews", "penalty", ["alpha=1e6"], "cvode-bdf", "1e-8"),
    ("wheel", "baumgarte", ["alpha=1e3", "beta=1e3", "gamma=1e3"], "cvode-bdf", "1e-8"),
    ("ball", "penalty", ["alpha=1e6"], "cvode-bdf", "1e-8"),
    ("slider-crank", "projection", [], "cvode-projection", "1e-8"),
    ("biped", "baumgarte", [], "ark-dirk-ark548", "1e-8"),
    ("andrews", "baumgarte", [], "msbdf", "1e-8"),
]


def run(cstab, case, dq, out):
    problem, method, params, integrator, tol = case
    cmd = [cstab, "run", "--problem", problem, "--method", method, "--integrator", integrator,
           "--rtol", tol, "--atol", tol, "--t-end", "ref", "--no-series", "--out", out]
    for p in params:
        cmd += ["--param", p]
    env = dict(os.environ)
    env.pop("CSTAB_JACOBIAN", None)
    if dq:
        env["CSTAB_JACOBIAN"] = "dq"
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, env=env)
    with open(os.path.join(out, "summary.csv")) as f:
        return next(csv.DictReader(f))


def jacobians(row):
    for key in ("cvode_jac_evals", "ark_jac_evals", "msbdf_system_jacobians"):
        if row.get(key):
            return row[key]
    return "-"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cstab", default=os.path.join(os.path.dirname(__file__), "..", "build", "release", "cli",
                                                    "cstab"))
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    if args.repeats < 1:
        print("jacobian-ratio: --repeats must be >= 1", file=sys.stderr)
        return 2
    print("| problem | method | integrator | tol | steps ad / dq | rhs ad / dq | Jacobians ad / dq "
          "| ref error ad / dq | wall ad (ms) | wall dq (ms) | dq / ad |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for case in CASES:
            walls = {False: [], True: []}
            rows = {}
            for k in range(args.repeats):
                for dq in (False, True):
                    row = run(args.cstab, case, dq, os.path.join(tmp, f"{k}{int(dq)}"))
                    if row["status"] != "ok":
                        print(f"jacobian-ratio: {case} ({'dq' if dq else 'ad'}) ended {row['status']}: "
                              f"{row['reason']}", file=sys.stderr)
                    walls[dq].append(float(row["wall_seconds"]))
                    rows[dq] = row
            ad, dq = rows[False], rows[True]
            if ad.get("jacobian") not in ("system", None) or dq.get("jacobian") != "dq":
                print(f"jacobian-ratio: {case}: jacobian columns {ad.get('jacobian')} / {dq.get('jacobian')}",
                      file=sys.stderr)
            wa, wd = statistics.median(walls[False]), statistics.median(walls[True])
            problem, method, params, integrator, tol = case
            name = method + (" " + " ".join(params) if params else "")
            print(f"| {problem} | {name} | {integrator} | {tol} | {ad['steps']} / {dq['steps']} "
                  f"| {ad['rhs_evals']} / {dq['rhs_evals']} | {jacobians(ad)} / {jacobians(dq)} "
                  f"| {float(ad['ref_error']):.2e} / {float(dq['ref_error']):.2e} "
                  f"| {wa * 1e3:.2f} | {wd * 1e3:.2f} | {wd / wa:.2f} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
