#!/usr/bin/env bash
# Builds the `sanitize` preset (ASan + UBSan, build/sanitize) and runs the
# whole test suite under it; any sanitizer report aborts the test that hit it.
# Extra arguments go to ctest. JOBS (default: nproc) sets the build and test
# parallelism; EXCLUDE_LABELS (a ctest label regex, default
# compile-fail|peers|plugins: the peers are not built there,
# peers/CMakeLists.txt; the plugin test compiles examples against an
# installed release-like package) the labels left out.
# SANITIZE_REUSE_RELEASE=1 (CI sets it) builds the release preset's problem
# pairs first (nothing to do after scripts/build.sh) and links their objects
# for the pairs that are not instrumented (CSTAB_SANITIZE_CLASSES) instead of
# compiling them again: docs/build.md.
set -euo pipefail
cd "$(dirname "$0")/.."
JOBS="${JOBS:-$(nproc)}"
start=$(date +%s)
reuse=""
if [[ ${SANITIZE_REUSE_RELEASE:-0} == 1 ]]; then
  cmake --preset release >/dev/null
  cmake --build build/release -j"$JOBS" --target cstab_problems
  reuse="$PWD/build/release"
fi
cmake --preset sanitize -DCSTAB_SANITIZE_REUSE="$reuse" >/dev/null
cmake --build build/sanitize -j"$JOBS"
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
# Two passes: every suite but the conformance suite first, then the
# conformance suite (method x problem pairs, most of the instrumented test
# time). Under CI's time budget (scripts/ci-sanitize.sh) a cut then falls on
# the conformance pairs, whose method code the release run also checks,
# rather than on the unit, regression and robustness suites of the
# hand-written layers.
excluded=${EXCLUDE_LABELS:-compile-fail|peers|plugins}
run_ctest() {
  (cd build/sanitize && ctest --output-on-failure -j"$JOBS" --timeout 1800 \
     -E 'GateMatrix.CommittedThresholdsPassOnTheGateMatrix' "$@") || status=$?
}
run_ctest -LE "$excluded|conformance" "$@"
run_ctest -L conformance -LE "$excluded" "$@"
end=$(date +%s)
echo "sanitize: build $((built - start)) s, tests $((end - built)) s, exit $status"
exit $status
