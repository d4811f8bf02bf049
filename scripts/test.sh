#!/usr/bin/env bash
# Builds everything and runs the whole test suite with ctest.
#
# Under CI (CI=true), or when asked locally, more configurations run after the main one:
#   - ASan+UBSan build (leak checks) of the whole suite    CONFORM_SANITIZE_TESTS=1 / CONFORM_SKIP_SANITIZE=1
#     (by default the core, membrane, import-isolation, lifetime and soak tests;
#     CONFORM_SANITIZE_ALL=1: the whole suite, about 50 min more on 2 cores)
#   - Debian's double-precision Bullet: plugin tests and   CONFORM_DOUBLE_TESTS=1   / CONFORM_SKIP_DOUBLE=1
#     the find_package install test (-DCONFORM_DOUBLE=ON)
#   - a bounded libFuzzer run of every tests/fuzz target    CONFORM_FUZZ_TESTS=1     / CONFORM_SKIP_FUZZ=1
#     (scripts/fuzz.sh; clang): a fixed number of inputs each (CONFORM_FUZZ_RUNS, by default
#     fuzz.sh's CI budgets) from seed CONFORM_FUZZ_SEED (1): deterministic, so that CI's verdict
#     does not depend on the machine
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${CONFORM_BUILD_DIR:-$root/build}"
jobs="$(nproc)"
ci="${CI:-false}"

"$root/scripts/build.sh"
ctest --test-dir "$build" --output-on-failure --parallel "$jobs" --timeout 900

generator=()
if command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi
werror=OFF
if [[ "$ci" == "true" ]]; then werror=ON; fi

# Builds the given test targets (and those in $extra_targets) in a second configuration and runs
# the tests matching a regex.
extra_targets=()
extra_configuration() {
  local dir="$1" regex="$2" pattern="$3"
  shift 3
  local log
  log="$(mktemp)"
  cmake -S "$root" -B "$dir" "${generator[@]}" -DCONFORM_BUILD_BENCHMARKS=OFF \
    -DCONFORM_WERROR="${stage_werror:-$werror}" "$@" >"$log" 2>&1 || { cat "$log"; return 1; }
  # The targets: the test sources matching $pattern (file names, not paths), in tests/ or in
  # one of its folders (tests/cga/, tests/plugin/, ...; fuzz/ holds no *_test.cpp).
  local targets patterns p names=()
  read -ra patterns <<<"$pattern"  # no globbing here: find matches the names
  for p in "${patterns[@]}"; do names+=(-o -name "$p"); done
  mapfile -t targets < <(find "$root/tests" -maxdepth 2 -type f \( "${names[@]:1}" \) -printf '%f\n' |
    sed 's/\.cpp$//' | sort)
  cmake --build "$dir" --parallel "$jobs" --target conform "${targets[@]}" "${extra_targets[@]}"
  ctest --test-dir "$dir" --output-on-failure --parallel "$jobs" --timeout 900 \
    -R "$regex" -E NOT_BUILT
}

# ASan reserves terabytes of address space for its shadow memory; where the machine forbids that
# (ulimit -v, strict overcommit) every sanitized test would fail at start-up, so probe first.
sanitizers_run() {
  local dir
  dir="$(mktemp -d)"
  echo 'int main() { return 0; }' >"$dir/probe.cpp"
  c++ -fsanitize=address,undefined "$dir/probe.cpp" -o "$dir/probe" >/dev/null 2>&1 &&
    "$dir/probe" >/dev/null 2>&1
  local rc=$?
  rm -rf "$dir"
  return $rc
}

if [[ "${CONFORM_SKIP_SANITIZE:-0}" != "1" && ( "$ci" == "true" || "${CONFORM_SANITIZE_TESTS:-0}" == "1" ) ]] &&
  ! sanitizers_run; then
  echo "conform: WARNING: an ASan+UBSan program cannot start on this machine (address-space limit?);" \
    "the sanitized core tests are skipped" >&2
  CONFORM_SKIP_SANITIZE=1
fi

# ASan+UBSan with leak detection (tests/sanitizer/lsan.supp: leaks inside third-party libraries
# only), on the core, membrane, import-isolation, lifetime and soak tests; CONFORM_SANITIZE_ALL=1
# runs the whole suite: every GoogleTest program, shell test and fuzz-regression replay, the
# install test included. Built at -O1 with line tables only (-g1), as ASan's documentation advises: on
# this 2-core machine that halves the cold build against RelWithDebInfo's -O2 -g (the membrane
# solver: 85 s against 156 s), which took 51 minutes for the whole suite; its 340 tests then ran
# in 8 minutes. CONFORM_SANITIZED=1 tells the few tests that size themselves to run smaller.
if [[ "${CONFORM_SKIP_SANITIZE:-0}" != "1" && ( "$ci" == "true" || "${CONFORM_SANITIZE_TESTS:-0}" == "1" ) ]]; then
  sanitize_start=$SECONDS
  sanitized_regex='^(cga_|ik_|membrane_|skin_alloc_test|io_broken_test|plugin_lifetime_test|plugin_soak_test)'
  sanitized_sources='cga_*_test.cpp ik_*_test.cpp membrane_*_test.cpp skin_alloc_test.cpp io_broken_test.cpp plugin_lifetime_test.cpp plugin_soak_test.cpp'
  # The whole suite sanitized took 50 min on 2 cores (2970 s, its build most of it), which with
  # the other stages passed CI's 90 min; CI runs the subset above, CONFORM_SANITIZE_ALL=1 all.
  if [[ "${CONFORM_SANITIZE_ALL:-0}" == "1" ]]; then
    sanitized_regex='.'
    sanitized_sources='*_test.cpp'
    extra_targets=(model_wire_replay scene_replay mesh_ops_replay)  # the fuzz regressions' ctests
  fi
  echo "conform: tests under ASan+UBSan ($sanitized_regex)"
  # Warnings are the main build's errors (-Werror at -O3 there); GCC's flow-based warnings differ
  # at -O1 with sanitizer instrumentation, and they are not what this stage checks.
  stage_werror=OFF ASAN_OPTIONS=detect_leaks=1 LSAN_OPTIONS="suppressions=$root/tests/sanitizer/lsan.supp" \
    UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 CONFORM_SANITIZED=1 \
    extra_configuration "$build-sanitize" "$sanitized_regex" "$sanitized_sources" \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" \
    -DCONFORM_SANITIZE=ON
  echo "conform: the sanitized stage took $((SECONDS - sanitize_start)) s"
  extra_targets=()
fi

if [[ "${CONFORM_SKIP_DOUBLE:-0}" != "1" && ( "$ci" == "true" || "${CONFORM_DOUBLE_TESTS:-0}" == "1" ) ]]; then
  echo "conform: plugin tests against double-precision Bullet"
  extra_configuration "$build-double" '^(plugin_|install_test)' 'plugin_*_test.cpp' \
    -DCMAKE_BUILD_TYPE=Release -DCONFORM_DOUBLE=ON
fi

# libFuzzer needs clang and its fuzzer runtime (libclang-rt-14-dev); probe both, as above.
fuzzer_runs() {
  local dir cxx
  cxx="$(command -v clang++-14 || command -v clang++ || true)"
  [[ -n "$cxx" ]] || return 1
  dir="$(mktemp -d)"
  echo 'extern "C" int LLVMFuzzerTestOneInput(const unsigned char*, unsigned long) { return 0; }' \
    >"$dir/probe.cpp"
  "$cxx" -fsanitize=fuzzer,address,undefined "$dir/probe.cpp" -o "$dir/probe" >/dev/null 2>&1 &&
    "$dir/probe" -runs=1 >/dev/null 2>&1
  local rc=$?
  rm -rf "$dir"
  return $rc
}

if [[ "${CONFORM_SKIP_FUZZ:-0}" != "1" && ( "$ci" == "true" || "${CONFORM_FUZZ_TESTS:-0}" == "1" ) ]]; then
  if fuzzer_runs; then
    echo "conform: fuzz targets, a fixed number of inputs each from seed ${CONFORM_FUZZ_SEED:-1}"
    CONFORM_FUZZ_BUILD_DIR="$build-fuzz" CONFORM_FUZZ_RUNS="${CONFORM_FUZZ_RUNS:-ci}" \
      "$root/scripts/fuzz.sh"
  else
    echo "conform: WARNING: clang's libFuzzer runtime is missing or cannot run here" \
      "(scripts/deps.sh installs clang-14 and libclang-rt-14-dev); the fuzz run is skipped" >&2
  fi
fi
