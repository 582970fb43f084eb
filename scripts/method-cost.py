#!/usr/bin/env python3
"""Marginal clean-build cost of each method, from a configured build tree.

    python3 scripts/method-cost.py [BUILD_DIR (build/release)] [METHOD ...]
    python3 scripts/method-cost.py [BUILD_DIR] --units REGEX

The second form measures every unit whose path matches REGEX (e.g.
'generated/models/' for the models' shared code) the same way, one line
each and their total.

A method's own units are its generated pair units (one per problem class,
and one per test problem class such as test_redundant's duplicated
pendulum) and its MethodInfo unit. Each is compiled alone with its command
from BUILD_DIR/compile_commands.json (ccache bypassed, output to a scratch
file), and its user+system CPU time is measured. The marginal cost on the
2-core machine is estimated as the CPU sum / 2: what one more method like it
adds to a clean build with `make -j2` (linking aside). The budget of issue
17 is 30 s per method.

Prints one line per method, slowest unit first, and a table at the end.
Run it on an otherwise idle machine; it takes about a minute per method.
"""
import json
import os
import re
import resource
import shlex
import subprocess
import sys
import tempfile


def method_slugs(root):
    """(name, slug) of every cstab_method line, in the catalog's order."""
    out = []
    with open(os.path.join(root, "methods", "CMakeLists.txt")) as f:
        for line in f:
            m = re.match(r"\s*cstab_method\((\S+)\s", line)
            if m:
                out.append((m.group(1), m.group(1).replace("-", "_")))
    return out


def cpu_of(command, cwd):
    """CPU seconds (user + sys) of one compile, measured on its children."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    env = dict(os.environ, CCACHE_DISABLE="1")
    subprocess.run(command, cwd=cwd, env=env, check=True,
                   stdout=subprocess.DEVNULL)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def scratch_command(entry, scratch):
    args = entry["arguments"] if "arguments" in entry else shlex.split(entry["command"])
    args = list(args)
    if "-o" in args:
        args[args.index("-o") + 1] = scratch
    # Drop a compiler launcher (ccache) in front of the compiler.
    if os.path.basename(args[0]) == "ccache":
        args = args[1:]
    return args


def units_cost(db, pattern):
    """CPU of every unit whose path matches PATTERN, one line each, and the total."""
    try:
        regex = re.compile(pattern)
    except re.error as e:
        print("method-cost: --units: bad regular expression '%s': %s" % (pattern, e), file=sys.stderr)
        sys.exit(2)
    units = [e for e in db if regex.search(e["file"])]
    if not units:
        print("method-cost: --units: no unit matches '%s'" % pattern, file=sys.stderr)
        sys.exit(2)
    total = 0.0
    with tempfile.TemporaryDirectory() as tmp:
        for e in units:
            cpu = cpu_of(scratch_command(e, os.path.join(tmp, "unit.o")), e["directory"])
            total += cpu
            print("%6.2f s  %s" % (cpu, os.path.relpath(e["file"], e["directory"])), flush=True)
    print("%d units  CPU %.1f s" % (len(units), total))


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    argv = sys.argv[1:]
    build = "build/release"
    if argv and os.path.isdir(argv[0]):
        build, argv = argv[0], argv[1:]
    db_path = os.path.join(build, "compile_commands.json")
    if not os.path.exists(db_path):
        sys.exit("method-cost: %s not found (configure %s first)" % (db_path, build))
    with open(db_path) as f:
        db = json.load(f)
    if argv[:1] == ["--units"]:
        if len(argv) != 2:
            sys.exit("usage: method-cost.py [BUILD_DIR] --units REGEX")
        units_cost(db, argv[1])
        return
    methods = method_slugs(root)
    known = {n for n, _ in methods}
    for name in argv:
        if name not in known:
            print("method-cost: unknown method '%s' (known: %s)" % (name, ", ".join(sorted(known))),
                  file=sys.stderr)
            sys.exit(2)
    if argv:
        methods = [(n, s) for n, s in methods if n in argv]
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        scratch = os.path.join(tmp, "unit.o")
        for name, slug in methods:
            pair = re.compile(r"/pairs/[A-Za-z0-9]+__%s\.cpp$" % re.escape(slug))
            info = "/generated/methods/%s.cpp" % slug
            units = [e for e in db if pair.search(e["file"]) or e["file"].endswith(info)]
            timed = []
            for e in units:
                timed.append((cpu_of(scratch_command(e, scratch), e["directory"]),
                              os.path.basename(e["file"])))
            timed.sort(reverse=True)
            total = sum(t for t, _ in timed)
            rows.append((name, len(timed), total, timed[0] if timed else (0, "")))
            print("%-22s %2d units  CPU %6.1f s  marginal %5.1f s  slowest %s %.1f s"
                  % (name, len(timed), total, total / 2, timed[0][1] if timed else "-",
                     timed[0][0] if timed else 0), flush=True)
    print()
    print("| method | units | CPU (s) | marginal, CPU / 2 (s) |")
    print("|---|---|---|---|")
    for name, n, total, _ in rows:
        print("| %s | %d | %.1f | %.1f |" % (name, n, total, total / 2))


if __name__ == "__main__":
    main()
