#!/usr/bin/env bash
# Runs benchmarks and writes their medians to benchmarks/results/<machine>.csv, one row per
# benchmark (like Box2D's per-machine results): the program, the benchmark, median real and CPU
# time, and every counter (the ratios against the baselines measured in the same run).
#
#   scripts/bench_csv.sh [--machine NAME] [--repetitions N] [PROGRAM[:FILTER] ...]
#
# PROGRAM is a benchmark program in $CONFORM_BUILD_DIR/benchmarks (default build/), FILTER a
# --benchmark_filter regex (default: all of it). Without programs: a quick selection. NAME
# defaults to the CPU model and core count, e.g. "amd-epyc-7b13-2c". The file is replaced.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${CONFORM_BUILD_DIR:-$root/build}"
repetitions=5
machine=""
programs=()
while (($#)); do
  case "$1" in
    --machine) machine="$2"; shift 2 ;;
    --repetitions) repetitions="$2"; shift 2 ;;
    -h | --help) sed -n '2,10p' "$0"; exit 0 ;;
    *) programs+=("$1"); shift ;;
  esac
done
if ((${#programs[@]} == 0)); then
  programs=("cga_bench:^BM_(MotorCompose|MotorPointBatch)$" "ik_bench:^BM_(ScalarFast|ArmIk)/double$"
    "tear_drill_bench:^BM_Tear100(Lips)?/faces:(0|50000)/index")
fi
if [[ -z "$machine" ]]; then
  cpu="$(lscpu 2>/dev/null | sed -n 's/^Model name:[[:space:]]*//p' | head -n1)"
  machine="$(tr 'A-Z' 'a-z' <<<"${cpu:-unknown-cpu}" |
    sed -E 's/\((r|tm)\)//g; s/(cpu|processor|[0-9]+-core)//g; s/@.*//; s/[^a-z0-9]+/-/g; s/^-+|-+$//g')"
  machine="$machine-$(nproc)c"
fi
out="$root/benchmarks/results/$machine.csv"
mkdir -p "$(dirname "$out")"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

i=0
for entry in "${programs[@]}"; do
  program="${entry%%:*}"
  filter="."
  [[ "$entry" == *:* ]] && filter="${entry#*:}"
  binary="$build/benchmarks/$program"
  [[ -x "$binary" ]] || { echo "bench_csv: $binary is not built" >&2; exit 1; }
  echo "bench_csv: $program --benchmark_filter='$filter'" >&2
  # The programs print their own ratio table on stdout; the JSON goes to a file.
  "$binary" --benchmark_filter="$filter" --benchmark_repetitions="$repetitions" \
    --benchmark_report_aggregates_only=true --benchmark_out="$work/$i.json" \
    --benchmark_out_format=json >/dev/null 2>&1
  echo "$program" >"$work/$i.name"
  i=$((i + 1))
done

python3 - "$work" "$i" "$machine" "$out" <<'PY'
import csv, json, sys
work, count, machine, out = sys.argv[1], int(sys.argv[2]), sys.argv[3], sys.argv[4]
standard = {"name", "run_name", "run_type", "repetitions", "repetition_index", "threads",
            "iterations", "real_time", "cpu_time", "time_unit", "aggregate_name",
            "aggregate_unit", "family_index", "per_family_instance_index", "label",
            "error_occurred", "error_message"}
with open(out, "w", newline="") as f:
    w = csv.writer(f)
    w.writerow(["machine", "date", "program", "benchmark", "median_real_time", "median_cpu_time",
                "time_unit", "repetitions", "counters"])
    for i in range(count):
        program = open(f"{work}/{i}.name").read().strip()
        data = json.load(open(f"{work}/{i}.json"))
        date = data["context"]["date"]
        for b in data["benchmarks"]:
            if b.get("aggregate_name") != "median":
                continue
            counters = ";".join(f"{k}={b[k]:.6g}" for k in sorted(b) if k not in standard
                                and isinstance(b[k], (int, float)))
            w.writerow([machine, date, program, b["run_name"], f"{b['real_time']:.6g}",
                        f"{b['cpu_time']:.6g}", b["time_unit"], b.get("repetitions", ""),
                        counters])
print(f"bench_csv: wrote {out}")
PY
