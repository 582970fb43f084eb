#!/usr/bin/env bash
# Builds the `sanitize` preset (ASan + UBSan, build/sanitize) and runs the
# whole test suite under it; any sanitizer report aborts the test that hit it.
# Extra arguments go to ctest. JOBS (default: nproc) sets the build and test
# parallelism; EXCLUDE_LABELS (a ctest label regex, default
# compile-fail|peers|plugins: the peers are not built there,
# peers/CMakeLists.txt; the plugin test compiles examples against an
# installed release-like package) the labels left out.
# SANITIZE_REUSE_RELEASE=1 (CI sets it) builds the release preset's problem
# pairs and test_redundant's first (nothing to do after scripts/build.sh) and
# links their objects for the pairs that are not instrumented
# (CSTAB_SANITIZE_CLASSES) instead of compiling them again: docs/build.md.
#
# Built and run in slices, so that a time budget's cut (scripts/ci-sanitize.sh)
# falls after some tests have run, not during the build of all of them:
#   1. the library, `cstab` and the tests of the layers over it (FIRST below:
#      the CLI, matrix, gate, score, tune and stability commands, the results'
#      files), which compile in seconds once the library is built;
#   2. every other test executable, and its tests but the conformance suite;
#   3. the conformance suite (method x problem pairs, most of the instrumented
#      test time; the release run checks the same method code).
set -euo pipefail
cd "$(dirname "$0")/.."
JOBS="${JOBS:-$(nproc)}"
start=$(date +%s)
reuse=""
if [[ ${SANITIZE_REUSE_RELEASE:-0} == 1 ]]; then
  cmake --preset release >/dev/null
  cmake --build build/release -j"$JOBS" --target cstab_problems test_redundant
  reuse="$PWD/build/release"
fi
cmake --preset sanitize -DCSTAB_SANITIZE_REUSE="$reuse" >/dev/null
FIRST="test_cli test_gate test_matrix test_trust test_score test_series_gz test_plots test_stability test_tune test_crash_consistency test_external"
first_re="^($(tr ' ' '|' <<<"$FIRST"))[.]"
cmake --build build/sanitize -j"$JOBS" --target cstab $FIRST
built=$(date +%s)
# halt_on_error: the first finding fails the test (UBSan is recoverable by
# default). detect_leaks: LeakSanitizer runs with ASan. The forked matrix
# workers inherit the options.
export ASAN_OPTIONS="halt_on_error=1:abort_on_error=1:detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1${ASAN_OPTIONS:+:$ASAN_OPTIONS}"
export UBSAN_OPTIONS="halt_on_error=1:abort_on_error=1:print_stacktrace=1${UBSAN_OPTIONS:+:$UBSAN_OPTIONS}"
status=0
# The gate's committed timing rows (cstab / IDA-GGL wall-time ratios) do not
# hold under instrumentation: ASan slows cstab's code, not the uninstrumented
# SUNDIALS library (measured 0.38 and 1.01 against bounds 0.2 and 0.6; every
# accuracy check of that test passed). The test is excluded here, the
# degraded-configuration gate test still runs.
# The compile-fail tests run the compiler on files that must not compile,
# without the sanitizers: the release run covers them.
# ctest names a test <executable>.<suite>.<test> (tests/CMakeLists.txt), so
# a slice is selected by its executables' names.
excluded=${EXCLUDE_LABELS:-compile-fail|peers|plugins}
skip='GateMatrix.CommittedThresholdsPassOnTheGateMatrix'
run_ctest() {
  (cd build/sanitize && ctest --output-on-failure -j"$JOBS" --timeout 1800 "$@") || status=$?
}
echo "sanitize: slice 1 ($FIRST) built in $((built - start)) s"
run_ctest -R "$first_re" -E "$skip" -LE "$excluded|conformance" "$@"
cmake --build build/sanitize -j"$JOBS"
built2=$(date +%s)
echo "sanitize: the rest built in $((built2 - built)) s"
run_ctest -E "$first_re|$skip" -LE "$excluded|conformance" "$@"
run_ctest -L conformance -LE "$excluded" "$@"
end=$(date +%s)
echo "sanitize: $((end - start)) s in all, exit $status"
exit $status
