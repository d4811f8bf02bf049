#!/usr/bin/env bash
# Configures and builds Conform into build/ (or $CONFORM_BUILD_DIR), installing missing Debian
# packages first. Extra arguments go to CMake's configure step.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${CONFORM_BUILD_DIR:-$root/build}"
"$root/scripts/deps.sh"
generator=()
if command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi
werror=OFF
if [[ "${CI:-}" == "true" ]]; then werror=ON; fi
if [[ -f "$build/CMakeCache.txt" ]]; then generator=(); fi  # keep the existing generator
log="$(mktemp)"
cmake -S "$root" -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release \
  -DCONFORM_WERROR="$werror" "$@" >"$log" 2>&1 ||
  { cat "$log"; exit 1; }
cmake --build "$build" --parallel "$(nproc)"
