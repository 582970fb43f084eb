#!/usr/bin/env bash
# Builds every libFuzzer target in tests/fuzz/ (clang-14, -DCSTAB_FUZZ=ON,
# ASan + UBSan, build/fuzz) and runs each for FUZZ_SECONDS (default 60) from
# a seed corpus: tests/fuzz/seeds/<target>/ if present, and for the
# fuzz_matrix_* targets also matrices/*.toml and the embedded default matrix.
# A crash, a sanitizer report, a timeout (> 10 s per input) or more than
# 2 GB of memory fails the script; the input is left in
# build/fuzz/artifacts/<target>/. Extra arguments go to every fuzzer.
set -euo pipefail
cd "$(dirname "$0")/.."
FUZZ_SECONDS="${FUZZ_SECONDS:-60}"
JOBS="${JOBS:-$(nproc)}"
root=$(pwd)
build=build/fuzz

start=$(date +%s)
CC=clang-14 CXX=clang++-14 cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCSTAB_FUZZ=ON -DCSTAB_BUILD_TESTS=OFF >/dev/null
cmake --build "$build" -j"$JOBS" --target cstab_fuzz
built=$(date +%s)
echo "fuzz: built in $((built - start)) s"

# The default matrix, as embedded in cli/matrix_commands.cpp.
seeds_common="$build/seeds/matrix"
rm -rf "$seeds_common" && mkdir -p "$seeds_common"
cp matrices/*.toml "$seeds_common/"
sed -n '/kDefaultMatrix = R"(/,/^)";/p' cli/matrix_commands.cpp | sed '1s/.*R"(//; $d' >"$seeds_common/default.toml"

status=0
for source in tests/fuzz/fuzz_*.cpp; do
  target=$(basename "$source" .cpp)
  corpus="$build/corpus/$target"
  artifacts="$build/artifacts/$target"
  mkdir -p "$corpus" "$artifacts"
  seeds=()
  [ -d "tests/fuzz/seeds/$target" ] && seeds+=("tests/fuzz/seeds/$target")
  [[ "$target" == fuzz_matrix* ]] && seeds+=("$seeds_common")
  dict=()
  [ -f "tests/fuzz/$target.dict" ] && dict=(-dict="tests/fuzz/$target.dict")
  [[ "$target" == fuzz_matrix* && -f tests/fuzz/matrix.dict ]] && dict=(-dict=tests/fuzz/matrix.dict)
  log="$build/$target.log"
  t0=$(date +%s)
  rc=0
  "$build/tests/fuzz/$target" -max_total_time="$FUZZ_SECONDS" -timeout=10 -rss_limit_mb=2048 -max_len=4096 \
    -print_final_stats=1 -artifact_prefix="$artifacts/" "${dict[@]}" "$@" "$corpus" "${seeds[@]}" >"$log" 2>&1 || rc=$?
  t1=$(date +%s)
  execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
  cov=$(grep -o 'cov: [0-9]* ft: [0-9]*' "$log" | tail -1 || echo "cov: ?")
  units=$(ls "$corpus" | wc -l)
  if [ "$rc" -ne 0 ]; then
    status=1
    echo "fuzz: $target: FAILED (exit $rc) after $((t1 - t0)) s, $execs executions; see $log and $artifacts"
    grep -m3 -E 'ERROR|SUMMARY|Test unit written' "$log" || true
  else
    echo "fuzz: $target: ok, $((t1 - t0)) s, $execs executions, $cov, corpus $units inputs, no crash"
  fi
done
echo "fuzz: total $(($(date +%s) - start)) s"
exit $status
