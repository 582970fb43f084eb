#!/usr/bin/env python3
"""How much of the build's CPU is the compiler's front end alone.

Compiles every translation unit of a built tree twice, with its command from
compile_commands.json: as the build does (-c -o), and with -fsyntax-only
(parsing and template instantiation, no code generation or optimization),
and prints the CPU seconds (user + system) of each, summed by kind of unit.
The front end's share is the floor of what any flag, optimization level or
linker can save: the clean build cannot take less than its front end's CPU
over the cores, whatever is done to code generation.

    python3 scripts/build-floor.py [BUILD_DIR] [JOBS] [UNITS_TSV]

BUILD_DIR defaults to build/release (built, so that its precompiled headers
exist), JOBS to the number of cores; CSTAB_FLOOR_ONLY=REGEX measures only
the units whose source path matches. UNITS_TSV, if given, receives one line
per unit: "full_cpu syntax_cpu source". Takes about half again the clean
build's CPU time (docs/build.md).
"""
import concurrent.futures
import json
import os
import re
import shlex
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def kind(path):
    rel = os.path.relpath(path, ROOT)
    if "generated/pairs/" in rel:
        return "pair units (problem class x method)"
    if "generated/tests/" in rel:
        return "tests' generated units"
    if "generated/models/" in rel:
        return "model units"
    if "generated/" in rel:
        return "other generated units"
    if rel.startswith("tests/"):
        return "test files"
    top = rel.split("/")[0]
    if top in ("core", "linalg", "methods", "problems", "harness"):
        return "libraries: core linalg methods problems harness"
    return "application: cli matrix report gate io plugin peers bench"


def cpu_of(argv, cwd):
    """CPU seconds (user + system) of the child that runs argv; None if it fails."""
    # wait4 reports this child's own usage, whatever else runs beside it.
    child = subprocess.Popen(argv, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _, status, usage = os.wait4(child.pid, 0)
    child.returncode = os.waitstatus_to_exitcode(status)
    return usage.ru_utime + usage.ru_stime if child.returncode == 0 else None


def measure(numbered, scratch):
    number, entry = numbered
    argv = shlex.split(entry["command"])
    i = argv.index("-o")
    obj = os.path.join(scratch, f"{number}.o")
    full = argv[:i + 1] + [obj] + argv[i + 2:]
    syntax = [a for j, a in enumerate(argv) if j not in (i, i + 1)]
    syntax[syntax.index("-c")] = "-fsyntax-only"
    a = cpu_of(full, entry["directory"])
    if os.path.exists(obj):
        os.remove(obj)
    b = cpu_of(syntax, entry["directory"])
    return entry["file"], a, b


def main():
    build = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "build/release")
    jobs = int(sys.argv[2]) if len(sys.argv) > 2 else os.cpu_count()
    out = sys.argv[3] if len(sys.argv) > 3 else None
    db = os.path.join(build, "compile_commands.json")
    if not os.path.exists(db):
        sys.exit(f"build-floor: {db} does not exist: configure and build {build} first")
    only = re.compile(os.environ.get("CSTAB_FLOOR_ONLY", ""))  # a regex on the source path, to try it out
    entries = [e for e in json.load(open(db)) if "cmake_pch" not in e["file"] and only.search(e["file"])]
    sums = {}
    lines = []
    failed = []
    with tempfile.TemporaryDirectory() as scratch, concurrent.futures.ThreadPoolExecutor(jobs) as pool:
        for path, a, b in pool.map(lambda e: measure(e, scratch), enumerate(entries)):
            if a is None or b is None:
                failed.append(path)
                continue
            k = kind(path)
            n, fa, fb = sums.get(k, (0, 0.0, 0.0))
            sums[k] = (n + 1, fa + a, fb + b)
            lines.append(f"{a:.2f} {b:.2f} {path}")
    if out:
        with open(out, "w") as f:
            f.write("\n".join(lines) + "\n")
    print(f"{'units':52} {'n':>4} {'full CPU':>9} {'front end':>10} {'share':>6}")
    tn, ta, tb = 0, 0.0, 0.0
    for k, (n, a, b) in sorted(sums.items(), key=lambda kv: -kv[1][1]):
        print(f"{k:52} {n:4d} {a:8.0f}s {b:9.0f}s {100 * b / a:5.0f}%")
        tn, ta, tb = tn + n, ta + a, tb + b
    print(f"{'total':52} {tn:4d} {ta:8.0f}s {tb:9.0f}s {100 * tb / ta:5.0f}%")
    print(f"front end alone over {jobs} cores, perfectly parallel: {tb / jobs:.0f} s")
    for path in failed:
        print(f"not measured (its command failed here): {path}")


if __name__ == "__main__":
    main()
