#!/usr/bin/env bash
# Plugins end to end (issue 21): `cmake --install` of the build under test,
# the examples built against the installed package, and what a user sees.
# Usage: test_plugins.sh BUILD_DIR SOURCE_DIR. Exit 0 only if every check holds.
set -uo pipefail
unset CSTAB_PLUGIN_PATH  # the caller's plugins are not this test's
build=$1
src=$2
work=$(mktemp -d /tmp/cstab-plugins.XXXXXX)
trap 'rm -rf "$work"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
pass() { echo "ok: $*"; }
# A number from a `cstab run` line: field NAME followed by its value.
field() { sed -n "s/.*$1 \([-0-9.e+]*\).*/\1/p" <<<"$2" | head -1; }
# awk's comparison of two numbers: lt A B is true if A < B.
lt() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a + 0 < b + 0) }'; }

prefix=$work/prefix
# Plugins are compiled by the compiler that compiled cstab (cstabConfig.cmake checks it).
cxx=$(sed -n 's/^CMAKE_CXX_COMPILER:[A-Z]*=//p' "$build/CMakeCache.txt")
[[ -n $cxx ]] || { echo "FAIL: no CMAKE_CXX_COMPILER in $build/CMakeCache.txt"; exit 1; }
cmake --install "$build" --prefix "$prefix" >/dev/null || { echo "FAIL: cmake --install"; exit 1; }
C=$prefix/bin/cstab
[[ -x $C ]] || { echo "FAIL: no installed cstab"; exit 1; }

# --- the examples, built against the installed package only
for ex in velocity_projection double_pendulum; do
  start=$(date +%s.%N)
  if ! { cmake -S "$src/examples/$ex" -B "$work/$ex" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_CXX_COMPILER="$cxx" >"$work/$ex.log" 2>&1 &&
         cmake --build "$work/$ex" -j"$(nproc)" >>"$work/$ex.log" 2>&1; }; then
    tail -30 "$work/$ex.log"
    echo "FAIL: building examples/$ex against the installed package"
    exit 1
  fi
  echo "built examples/$ex in $(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }') s"
done
VP=$work/velocity_projection/velocity_projection.so
DP=$work/double_pendulum/double_pendulum.so
P=(--plugin "$VP" --plugin "$DP")

# --- a plugin configured with another compiler than cstab's: a configure-time error naming the right one
other=g++
[[ $cxx == *clang* ]] || other=clang++-14
if command -v "$other" >/dev/null; then
  if cmake -S "$src/examples/velocity_projection" -B "$work/other-cxx" -DCMAKE_PREFIX_PATH="$prefix" \
       -DCMAKE_CXX_COMPILER="$other" >"$work/other-cxx.log" 2>&1; then
    fail "configuring a plugin with $other (cstab: $cxx) succeeded"
  elif grep -q -- "-DCMAKE_CXX_COMPILER=$cxx" "$work/other-cxx.log"; then
    pass "another compiler ($other): configure error naming $cxx"
  else
    fail "configuring with $other failed without naming $cxx: $(grep -m1 -A3 'CMake Error' "$work/other-cxx.log")"
  fi
fi

# --- cstab list says where each came from
list=$("$C" list "${P[@]}")
grep -q "^  velocity-projection: " <<<"$list" && grep -q "from plugin $VP" <<<"$list" &&
  pass "list: velocity-projection from $VP" || fail "list does not show velocity-projection's plugin"
grep -q "^  double-pendulum: " <<<"$list" && grep -q "from plugin $DP" <<<"$list" &&
  pass "list: double-pendulum from $DP" || fail "list does not show double-pendulum's plugin"
# (Captured first: `cstab list | grep -q` could end the pipe before cstab
# flushes its last bytes, and a SIGPIPE would fail the pipeline.)
list_env=$(CSTAB_PLUGIN_PATH="$VP:$DP" "$C" list)
grep -q "from plugin $DP" <<<"$list_env" && pass "CSTAB_PLUGIN_PATH loads plugins" || fail "CSTAB_PLUGIN_PATH"

# --- the plugin problem against its independent reference (the rod angles'
# ODE): the Cartesian model integrated tightly agrees with it at t = 5.
out=$("$C" run "${P[@]}" --problem double-pendulum --method projection --integrator rk8pd --rtol 1e-10 \
      --atol 1e-10 --t-end ref --out "$work/dp" 2>&1)
err=$(field "error at t=5" "$out"); de=$(field "max |dE|" "$out"); res=$(field "max residual" "$out")
echo "double-pendulum / projection / rk8pd 1e-10: error $err, max |dE| $de, max residual $res"
[[ -n $err && -n $de && -n $res ]] && lt "$err" 1e-9 && lt "$de" 1e-8 && lt "$res" 1e-10 &&
  pass "double-pendulum agrees with its angle-form reference" || fail "double-pendulum reference: $out"

# --- the plugin method against the built-ins on a built-in problem: velocity
# projection removes the velocity drift that feeds `none`'s quadratic
# position drift, and is itself above `projection` (positions not projected).
declare -A r
for m in none velocity-projection projection; do
  out=$("$C" run "${P[@]}" --problem pendulum --method $m --integrator rk4 --step 1e-2 --t-end 50 \
        --out "$work/pend-$m" 2>&1)
  r[$m]=$(field "max residual" "$out")
  echo "pendulum / $m / rk4 h = 1e-2, t = 50: max residual ${r[$m]}"
done
[[ -n ${r[none]} && -n ${r[velocity-projection]} && -n ${r[projection]} ]] &&
  lt "${r[velocity-projection]}" "$(awk -v a="${r[none]}" 'BEGIN { print a / 10 }')" &&
  lt "${r[projection]}" "${r[velocity-projection]}" &&
  pass "residual ordering projection < velocity-projection < none / 10" || fail "residual ordering"

# A plugin method on a plugin problem: neither was built for the other.
"$C" run "${P[@]}" --problem double-pendulum --method velocity-projection --integrator rk4 --step 1e-3 \
  --t-end 1 --out "$work/cross" 2>"$work/cross.err"
rc=$?
[[ $rc == 2 && ! -e $work/cross ]] && grep -q "not built for this problem" "$work/cross.err" &&
  pass "a plugin method on a plugin problem: refused, exit 2" || fail "cross plugin: rc $rc $(cat "$work/cross.err")"

# --- a matrix with plugins: cached while the plugin is the same file, rerun
# when it is rebuilt with other code (only its cases).
cp "$VP" "$work/vp.so"
cp "$DP" "$work/dp.so"
cat >"$work/m.toml" <<'TOML'
[defaults]
plugins = ["vp.so", "dp.so"]
t_end = 5
integrators = ["rk4"]
step = [1e-2, 1e-3]

[[sweep]]
name = "plugin-problem"
problems = ["double-pendulum"]
methods = ["projection", "baumgarte"]

[[sweep]]
name = "plugin-method"
problems = ["pendulum"]
methods = ["velocity-projection", "none"]
TOML
summary() { grep -o "[0-9]* run, [0-9]* cached" <<<"$1" | head -1; }
s1=$(summary "$("$C" matrix "$work/m.toml" --out "$work/mr" --jobs 2 --no-report 2>&1)")
s2=$(summary "$("$C" matrix "$work/m.toml" --out "$work/mr" --jobs 2 --no-report 2>&1)")
echo "matrix: first '$s1', again '$s2'"
[[ $s1 == "8 run, 0 cached" && $s2 == "0 run, 8 cached" ]] && pass "matrix with plugins: cached on rerun" ||
  fail "matrix caching: '$s1' then '$s2'"
grep -q "^plugins: .*vp.so (.*method velocity-projection)" "$work/mr/provenance.txt" &&
  grep -q "dp.so (.*problem double-pendulum)" "$work/mr/provenance.txt" &&
  pass "provenance records each plugin" || fail "provenance: $(grep plugins "$work/mr/provenance.txt")"
# The method rebuilt with other code (its description changed).
cp -r "$src/examples/velocity_projection" "$work/vp2-src"
sed -i 's/(example plugin)/(example plugin, rebuilt)/' "$work/vp2-src/velocity_projection.hpp"
cmake -S "$work/vp2-src" -B "$work/vp2" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_CXX_COMPILER="$cxx" >/dev/null 2>&1 &&
  cmake --build "$work/vp2" -j"$(nproc)" >/dev/null 2>&1 || fail "rebuilding velocity_projection"
cp "$work/vp2/velocity_projection.so" "$work/vp.so"
s3=$(summary "$("$C" matrix "$work/m.toml" --out "$work/mr" --jobs 2 --no-report 2>&1)")
echo "matrix after the rebuilt plugin: '$s3'"
[[ $s3 == "2 run, 6 cached" ]] && pass "a rebuilt plugin reruns its cases only" || fail "rebuilt plugin: '$s3'"

# --- cstab check: the examples pass every check; three deliberately wrong
# plugins fail, each for its reason (tests/plugins/bad_*).
for so in "$VP" "$DP"; do
  "$C" check --plugin "$so" >"$work/check.out" 2>&1
  rc=$?
  [[ $rc == 0 ]] && grep -q ", 0 FAIL$" "$work/check.out" && pass "check $(basename "$so"): $(tail -1 "$work/check.out")" ||
    { cat "$work/check.out"; fail "check $(basename "$so"): exit $rc"; }
done
for b in bad_jacobian bad_methods; do
  cmake -S "$src/tests/plugins/$b" -B "$work/$b" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_CXX_COMPILER="$cxx" >"$work/$b.log" 2>&1 &&
    cmake --build "$work/$b" -j"$(nproc)" >>"$work/$b.log" 2>&1 || { tail -20 "$work/$b.log"; fail "building $b"; }
done
expect_check() {  # expect_check SO ROW_REGEX WHAT: exit 1 and a FAIL row matching ROW_REGEX
  "$C" check --plugin "$1" >"$work/check.out" 2>&1
  local rc=$?
  if [[ $rc == 1 ]] && grep -Eq "$2" "$work/check.out"; then
    pass "check catches $3: $(grep -E "$2" "$work/check.out" | head -1 | tr -s ' ')"
  else
    cat "$work/check.out"
    fail "check did not catch $3 (exit $rc)"
  fi
}
expect_check "$work/bad_jacobian/bad_jacobian.so" "^wrong-jacobian +none +derivatives +FAIL +d2/dt2 length" \
  "a wrong closed-form Jacobian"
expect_check "$work/bad_methods/allocating_none.so" "^pendulum +allocating-none +allocation +FAIL +[1-9][0-9]* heap allocations" \
  "an allocating step"
grep -Eq "^pendulum +allocating-none +conformance +pass" "$work/check.out" &&
  pass "the allocating method fails only its allocation check" || fail "allocating-none: conformance should pass"
expect_check "$work/bad_methods/ignores_constraints.so" \
  "^pendulum +ignores-constraints +conformance +FAIL +rk8pd tol 1e-10; final residual [0-9.e+]+ >= 1e-06" \
  "a method that ignores the constraint"
"$C" check >/dev/null 2>"$work/check.err"
[[ $? == 2 ]] && grep -q "nothing to check" "$work/check.err" && pass "check without a plugin: exit 2" ||
  fail "check without a plugin: $(cat "$work/check.err")"

# --- bad plugins: one line naming the file and the reason, exit 2, nothing written
inc=(-I"$prefix/include/cstab" -I/usr/include/eigen3)
bad_so() {  # bad_so NAME SOURCE: a shared object from SOURCE
  printf '%s\n' "$2" >"$work/$1.cpp"
  "$cxx" -std=c++20 -shared -fPIC "${inc[@]}" "$work/$1.cpp" -o "$work/$1.so" || fail "compiling $1"
}
entry='#include "plugin/api.hpp"
extern "C" const char* cstab_plugin_build_id(void) { return CSTAB_PLUGIN_BUILD; }'
bad_so abi "$entry
extern \"C\" int cstab_plugin_abi(void) { return CSTAB_PLUGIN_ABI + 1; }
extern \"C\" void cstab_plugin_register(cstab::PluginRegistrar*) {}"
bad_so build_id '#include "plugin/api.hpp"
extern "C" const char* cstab_plugin_build_id(void) { return "0.0.1-0123456789abcdef"; }
extern "C" int cstab_plugin_abi(void) { return CSTAB_PLUGIN_ABI; }
extern "C" void cstab_plugin_register(cstab::PluginRegistrar*) {}'
bad_so clash "$entry
extern \"C\" int cstab_plugin_abi(void) { return CSTAB_PLUGIN_ABI; }
extern \"C\" void cstab_plugin_register(cstab::PluginRegistrar* r) {
  r->add_method(cstab::MethodInfo{\"baumgarte\", \"a second baumgarte\", {}}, {});
}"
bad_so missing_symbol "$entry
extern \"C\" int cstab_plugin_abi(void) { return CSTAB_PLUGIN_ABI; }
extern \"C\" void cstab_no_such_function_in_cstab(void);
extern \"C\" void cstab_plugin_register(cstab::PluginRegistrar*) { cstab_no_such_function_in_cstab(); }"
bad_so empty "$entry
extern \"C\" int cstab_plugin_abi(void) { return CSTAB_PLUGIN_ABI; }
extern \"C\" void cstab_plugin_register(cstab::PluginRegistrar*) {}"
bad_so bad_name "$entry
extern \"C\" int cstab_plugin_abi(void) { return CSTAB_PLUGIN_ABI; }
extern \"C\" void cstab_plugin_register(cstab::PluginRegistrar* r) {
  r->add_method(cstab::MethodInfo{\"a b\", \"a name with a space\", {}}, {});
}"
libm=$(ls /lib/*/libm.so.6 /usr/lib/*/libm.so.6 2>/dev/null | head -1)
check_bad() {  # check_bad WHAT PATH EXPECTED_TEXT
  local o=$work/out-$1
  "$C" run --plugin "$2" --problem pendulum --method baumgarte --integrator rk4 --step 1e-3 --t-end 1 \
    --out "$o" >"$work/$1.stdout" 2>"$work/$1.stderr"
  local rc=$? lines
  lines=$(wc -l <"$work/$1.stderr")
  if [[ $rc == 2 && $lines == 1 && ! -e $o ]] && grep -q -- "$3" "$work/$1.stderr"; then
    pass "$1: $(cat "$work/$1.stderr")"
  else
    fail "$1: exit $rc, $lines lines: $(cat "$work/$1.stderr")"
  fi
}
check_bad missing-file "$work/no-such.so" "plugin $work/no-such.so: no such file"
check_bad not-a-plugin "$libm" "not a cstab plugin"
check_bad not-elf "$work/m.toml" "cannot be loaded: invalid ELF header"
check_bad abi-mismatch "$work/abi.so" "built for plugin ABI"
check_bad build-id-mismatch "$work/build_id.so" "built against another cstab (build id 0.0.1-0123456789abcdef"
check_bad name-clash "$work/clash.so" "method 'baumgarte' is already defined (built in)"
check_bad missing-symbol "$work/missing_symbol.so" "undefined symbol: cstab_no_such_function_in_cstab"
check_bad registers-nothing "$work/empty.so" "registers no method and no problem"
check_bad bad-name "$work/bad_name.so" "method name 'a b': use letters, digits"
# The same method from two files.
cp "$VP" "$work/vp-copy.so"
"$C" list --plugin "$VP" --plugin "$work/vp-copy.so" >/dev/null 2>"$work/dup.err"
rc=$?
[[ $rc == 2 ]] && grep -q "method 'velocity-projection' is already defined (by $VP)" "$work/dup.err" &&
  pass "duplicate: $(cat "$work/dup.err")" || fail "duplicate: exit $rc $(cat "$work/dup.err")"

echo "$failures failure(s)"
exit $((failures > 0))
