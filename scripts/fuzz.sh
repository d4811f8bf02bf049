#!/usr/bin/env bash
# Builds the libFuzzer targets of tests/fuzz (clang, -fsanitize=fuzzer,address,undefined) and runs
# each for a bounded time (or number of inputs) on its checked-in corpus and regression inputs.
# Usage: scripts/fuzz.sh [SECONDS_PER_TARGET] [TARGET...]   (default 20 s; all targets)
#   CONFORM_FUZZ_RUNS       instead of a time: this many inputs per target ("ci": each
#                           target's CI budget below), from seed CONFORM_FUZZ_SEED (default 1),
#                           starting from the checked-in inputs only: the same run, and the
#                           same verdict, on every machine
#   CONFORM_FUZZ_BUILD_DIR  build folder (default build-fuzz beside build/)
#   CONFORM_FUZZ_JOBS       parallel build jobs (default: the cores)
#   CONFORM_FUZZ_RSS_MB     libFuzzer's memory cap per input (default 2048)
# New inputs that raise coverage go to $build/corpus/<target>/ (not to the checked-in corpus);
# a crasher is written to $build/artifacts/ and fails the run: copy it to
# tests/fuzz/regressions/<target>/ with the fix. Exit status: 0, or 1 on a finding or error.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${CONFORM_FUZZ_BUILD_DIR:-$root/build-fuzz}"
seconds="${1:-20}"
shift || true
targets=("$@")
((${#targets[@]})) || targets=(model_wire scene mesh_ops)
cxx="$(command -v clang++-14 || command -v clang++ || true)"
[[ -n "$cxx" ]] || { echo "fuzz: clang++ not found (scripts/deps.sh installs clang-14)" >&2; exit 1; }

generator=()
if command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi
log="$(mktemp)"
# -O1 with line tables: fast to build, and stack traces that name the line.
cmake -S "$root" -B "$build" "${generator[@]}" -DCMAKE_CXX_COMPILER="$cxx" -DCONFORM_FUZZ=ON \
  -DCONFORM_BUILD_TESTS=OFF -DCONFORM_BUILD_BENCHMARKS=OFF -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -gline-tables-only" >"$log" 2>&1 || { cat "$log"; exit 1; }
cmake --build "$build" --parallel "${CONFORM_FUZZ_JOBS:-$(nproc)}" \
  --target "${targets[@]/%/_fuzz}" >"$log" 2>&1 || { tail -50 "$log"; exit 1; }
rm -f "$log"

# A time budget explores further on a fast machine; a run count with a seed is reproducible.
# CI's budgets, about 20 s each on 2 cores: mesh_ops runs some 50 inputs a second (whole
# meshes cut, torn and checked), the others 10-25 thousand.
declare -A ci_runs=([model_wire]=200000 [scene]=100000 [mesh_ops]=1000)
runs="${CONFORM_FUZZ_RUNS:-}"

status=0
for t in "${targets[@]}"; do
  if [[ -n "$runs" ]]; then
    n="$runs"
    [[ "$runs" == ci ]] && n="${ci_runs[$t]}"
    budget=(-runs="$n" -seed="${CONFORM_FUZZ_SEED:-1}")
    what="$n inputs from seed ${CONFORM_FUZZ_SEED:-1}"
  else
    budget=(-max_total_time="$seconds")
    what="${seconds} s"
  fi
  mkdir -p "$build/corpus/$t" "$build/artifacts"
  found="$build/corpus/$t"  # where libFuzzer writes the inputs that reach new code
  if [[ -n "$runs" ]]; then found="$build/corpus-seeded/$t" && rm -rf "$found" && mkdir -p "$found"; fi
  inputs=("$found" "$root/tests/fuzz/corpus/$t")
  [[ -d "$root/tests/fuzz/regressions/$t" ]] && inputs+=("$root/tests/fuzz/regressions/$t")
  out="$build/$t.log"
  # Leaks are the sanitized suite's concern; here a leak report would stop the run at once.
  if ASAN_OPTIONS=detect_leaks=0 UBSAN_OPTIONS=print_stacktrace=1 \
    "$build/tests/fuzz/${t}_fuzz" "${budget[@]}" -rss_limit_mb="${CONFORM_FUZZ_RSS_MB:-2048}" \
      -timeout=30 -print_final_stats=1 -artifact_prefix="$build/artifacts/$t-" "${inputs[@]}" \
      >"$out" 2>&1; then
    executed="$(grep -o 'stat::number_of_executed_units: [0-9]*' "$out" | grep -o '[0-9]*$' || echo '?')"
    cov="$(grep -o 'cov: [0-9]*' "$out" | tail -1 | grep -o '[0-9]*$' || echo '?')"
    echo "fuzz: $t: $executed inputs ($what), coverage $cov edges, no finding"
  else
    status=1
    echo "fuzz: $t: FINDING (log $out); the input is in $build/artifacts/:" >&2
    grep -E 'ERROR|fuzz: property|SUMMARY|Test unit written' "$out" | head -20 >&2 || tail -30 "$out" >&2
  fi
done
exit $status
