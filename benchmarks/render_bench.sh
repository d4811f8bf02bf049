#!/usr/bin/env bash
# Rendering against simulating, in the same runs: the default scene (`conform` with no arguments
# runs tear-opening) N times with its pictures, video and run.glb and N times with --no-render,
# alternately. Prints the median wall and CPU seconds of each, their ratio (the slowdown), and
# from the rendered runs' summary.json the render time per picture against the simulation's
# time per step.
# Usage: benchmarks/render_bench.sh <conform> [N=5] [extra conform run args...]
set -euo pipefail
conform="$(realpath "$1")"
n="${2:-5}"
shift $(( $# >= 2 ? 2 : 1 ))
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
median() { sort -g | awk '{ a[NR] = $1 } END { print (NR % 2 ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2) }'; }
for i in $(seq "$n"); do
  for mode in render norender; do
    args=(run tear-opening --out "$tmp/$mode$i" "$@")
    [[ $mode == norender ]] && args+=(--no-render)
    /usr/bin/time -f "%e %U %S" -o "$tmp/$mode$i.time" "$conform" "${args[@]}" > /dev/null
    read -r wall user sys < "$tmp/$mode$i.time"
    echo "$wall" >> "$tmp/$mode.wall"
    echo "$user $sys" | awk '{ print $1 + $2 }' >> "$tmp/$mode.cpu"
  done
  # summary.json is written by nlohmann-json with one key per line: no JSON tool needed.
  key() { grep -o "\"$1\": [0-9.e+-]*" "$tmp/render$i/summary.json" | head -1 | awk '{ print $2 }'; }
  echo "$(key render_ms_per_picture) $(key sim_ms_per_step) $(key f3d_ms_per_panel)" \
    "$(key compose_ms) $(key glb_ms)" >> "$tmp/figures"
done
rw=$(median < "$tmp/render.wall"); nw=$(median < "$tmp/norender.wall")
rc=$(median < "$tmp/render.cpu"); nc=$(median < "$tmp/norender.cpu")
echo "runs: $n each; load average: $(cut -d' ' -f1-3 /proc/loadavg)"
echo "wall s (median): render $rw, no render $nw, slowdown $(awk -v a="$rw" -v b="$nw" 'BEGIN { printf "%.2f", a / b }')x"
echo "cpu s (median):  render $rc, no render $nc, slowdown $(awk -v a="$rc" -v b="$nc" 'BEGIN { printf "%.2f", a / b }')x"
if [[ -s $tmp/figures ]]; then
  for k in 1 2 3 4 5; do cut -d' ' -f"$k" "$tmp/figures" | median; done | paste -sd' ' | awk '{
    printf "render ms per picture %.0f (f3d ms per panel %.0f, compose ms %.0f, glb ms %.0f)\n", $1, $3, $4, $5
    printf "sim ms per step %.2f; one picture costs %.0f steps\n", $2, $1 / $2 }'
fi
