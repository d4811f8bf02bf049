#!/usr/bin/env bash
# Builds everything and runs the whole test suite with ctest. Under CI (CI=true) warnings are
# errors, and the core tests are run once more in an ASan+UBSan build (skip with
# CONFORM_SKIP_SANITIZE=1; force it locally with CONFORM_SANITIZE_TESTS=1).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${CONFORM_BUILD_DIR:-$root/build}"
"$root/scripts/build.sh"
ctest --test-dir "$build" --output-on-failure --parallel "$(nproc)" --timeout 600

if [[ "${CONFORM_SKIP_SANITIZE:-0}" != "1" && ( "${CI:-}" == "true" || "${CONFORM_SANITIZE_TESTS:-0}" == "1" ) ]]; then
  echo "conform: ASan+UBSan build of the core tests"
  san="$build-sanitize"
  generator=()
  if command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi
  cmake -S "$root" -B "$san" "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCONFORM_SANITIZE=ON -DCONFORM_BUILD_BENCHMARKS=OFF >/dev/null
  mapfile -t core_tests < <(cd "$root/tests" && ls cga_*_test.cpp ik_*_test.cpp 2>/dev/null | sed 's/\.cpp$//')
  cmake --build "$san" --parallel "$(nproc)" --target "${core_tests[@]}"
  ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    ctest --test-dir "$san" --output-on-failure --parallel "$(nproc)" --timeout 900 \
      -R '^(cga_|ik_)' -E NOT_BUILT
fi
