#!/usr/bin/env bash
# Configures and builds Conform into build/ (or $CONFORM_BUILD_DIR), installing missing Debian
# packages first (scripts/deps.sh).
# Usage: scripts/build.sh [--profile all|run] [CMake configure arguments...]
#   all (default)  every package, every target: libraries, conform, tests, benchmarks, the
#                  Python module; configuring fails if the packages of any of them are missing
#   run            only the packages of `conform` and its default scene, only the target conform
#                  (scripts/run.sh)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${CONFORM_BUILD_DIR:-$root/build}"
profile=all
if [[ "${1:-}" == "--profile" ]]; then
  profile="${2:?--profile needs all or run}"
  shift 2
fi
case "$profile" in
  all) require_all=ON; targets=() ;;
  run) require_all=OFF; targets=(--target conform) ;;
  *) echo "usage: scripts/build.sh [--profile all|run] [CMake arguments...]" >&2; exit 2 ;;
esac
"$root/scripts/deps.sh" "$profile"
generator=()
if command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi
werror=OFF
if [[ "${CI:-}" == "true" ]]; then werror=ON; fi
if [[ -f "$build/CMakeCache.txt" ]]; then generator=(); fi  # keep the existing generator
log="$(mktemp)"
cmake -S "$root" -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release \
  -DCONFORM_WERROR="$werror" -DCONFORM_REQUIRE_ALL="$require_all" "$@" >"$log" 2>&1 ||
  { cat "$log"; rm -f "$log"; exit 1; }
rm -f "$log"
cmake --build "$build" --parallel "$(nproc)" "${targets[@]}"
