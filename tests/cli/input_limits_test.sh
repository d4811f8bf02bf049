#!/usr/bin/env bash
# Bounded inputs and outputs, finite results, events inside the run: every input file (scene
# file, scalpel CSV, a sweep's scene) is refused unless it is a regular file within the size
# cap, a scalpel CSV is read strictly, results that are not finite are never written, frame
# counts and output sizes are capped before anything is written, and an event after a scene's
# last step is refused in every scene alike.
# Usage: bash input_limits_test.sh <conform> <source dir> <build dir>
set -euo pipefail
conform="$(realpath "$1")"
tmp="$(realpath "$(mktemp -d)")"
trap 'rm -rf "$tmp"' EXIT
fail() { echo "input_limits_test: $*" >&2; exit 1; }

# expect_refused <stderr pattern> <args...>: a non-zero exit below 128 (not a hang: 60 s at
# most; a reader of /dev/zero is given 4 GiB of address space, not the machine's memory), the
# pattern in the error, and nothing at $tmp/out.
expect_refused() {
  local pattern="$1" rc=0; shift
  rm -rf "$tmp/out"
  (
    [[ -n "${CONFORM_SANITIZED:-}" ]] || ulimit -v 4194304
    exec timeout 60 "$conform" "$@"
  ) > "$tmp/stdout" 2> "$tmp/stderr" < /dev/null || rc=$?
  if [[ $rc -eq 0 || $rc -ge 124 ]] || ! grep -q -- "$pattern" "$tmp/stderr"; then
    cat "$tmp/stderr" >&2
    fail "$* gave rc $rc, expected an error with '$pattern'"
  fi
  [[ ! -e "$tmp/out" ]] || fail "$* wrote $tmp/out despite the error"
}

# --- inputs that are not regular files, or too large -------------------------------------------
mkfifo "$tmp/fifo.json" "$tmp/fifo.csv"
expect_refused "scene file $tmp/fifo.json is a FIFO, not a regular file" run "$tmp/fifo.json" --out "$tmp/out"
expect_refused "scene file /dev/zero is a character device, not a regular file" run /dev/zero --out "$tmp/out"
expect_refused "scene file $tmp/fifo.json is a FIFO" sweep "$tmp/fifo.json" --grid seed=1,2 --out "$tmp/out"
expect_refused "scalpel file $tmp/fifo.csv is a FIFO, not a regular file" \
  tear arm --scalpel "$tmp/fifo.csv" --out "$tmp/out"
expect_refused "scalpel file /dev/zero is a character device" tear arm --scalpel /dev/zero --out "$tmp/out"
expect_refused "scene file $tmp is a directory" run "$tmp" --out "$tmp/out"
# The cap: 16 MiB by default, CONFORM_MAX_INPUT_MIB sets it.
truncate -s 17M "$tmp/huge.json"
expect_refused "scene file $tmp/huge.json is 17825792 bytes, more than the cap of 16777216 bytes" run "$tmp/huge.json" --out "$tmp/out"
"$conform" scenes --show arm-track > "$tmp/arm.json"
CONFORM_MAX_INPUT_MIB=0.001 expect_refused "bytes, more than the cap of 1048 bytes (16 MiB by default; CONFORM_MAX_INPUT_MIB sets it)" \
  run "$tmp/arm.json" --out "$tmp/out"
CONFORM_MAX_INPUT_MIB=lots expect_refused "CONFORM_MAX_INPUT_MIB='lots' must be a positive number" \
  run "$tmp/arm.json" --out "$tmp/out"
"$conform" run "$tmp/arm.json" --steps 2 --set outputs.plots=false --no-render --out "$tmp/ok" \
  > /dev/null 2> "$tmp/err" || { cat "$tmp/err" >&2; fail "a regular scene file under the cap was refused"; }

# --- scalpel CSVs, strictly ----------------------------------------------------------------------
scalpel() {  # scalpel <file> <rows...>: the header, then the rows
  local f="$1"; shift
  printf 't,ax,ay,az,bx,by,bz\n' > "$f"
  for row in "$@"; do printf '%s\n' "$row" >> "$f"; done
}
scalpel "$tmp/nine.csv" "0,0,0,0.1,0.2,0.03,0.1,7,8"
expect_refused "$tmp/nine.csv:2: 9 cells, expected 7" tear arm --scalpel "$tmp/nine.csv" --out "$tmp/out"
scalpel "$tmp/abc.csv" "0,0,0,0.1,0.2,0.03,0.1" "0abc,0,0,0.1,0.2,0.03,0.1"
expect_refused "$tmp/abc.csv:3: column 1 (t): '0abc' is not a finite number" \
  tear arm --scalpel "$tmp/abc.csv" --out "$tmp/out"
scalpel "$tmp/inf.csv" "0,0,0,0.1,inf,0.03,0.1"
expect_refused "$tmp/inf.csv:2: column 5 (bx): 'inf' is not a finite number" \
  tear arm --scalpel "$tmp/inf.csv" --out "$tmp/out"
scalpel "$tmp/short.csv" "0,0,0,0.1,0.2,0.03"
expect_refused "$tmp/short.csv:2: 6 cells, expected 7" tear arm --scalpel "$tmp/short.csv" --out "$tmp/out"
scalpel "$tmp/header.csv"
expect_refused "$tmp/header.csv: no rows" tear arm --scalpel "$tmp/header.csv" --out "$tmp/out"

# --- finite or refused ---------------------------------------------------------------------------
# mesh_cli_test's stroke: 50 samples along the arm, crossing its +x wall.
scalpel "$tmp/good.csv"
awk 'BEGIN { for (i = 0; i < 50; ++i) { z = 0.1 + 0.1 * i / 49; print i ",0,0," z ",0.2,0.03," z } }' \
  >> "$tmp/good.csv"
expect_refused "--open 1e+308 is more than the model's size" \
  tear arm --scalpel "$tmp/good.csv" --open 1e308 --out "$tmp/out"
"$conform" tear arm --scalpel "$tmp/good.csv" --open 0.004 --out "$tmp/torn" > /dev/null 2> "$tmp/err" ||
  { cat "$tmp/err" >&2; fail "the good scalpel with a small opening was refused"; }
grep -q null "$tmp/torn/summary.json" && fail "tear's summary.json holds null"
expect_refused "--upper 1e+300 must be a length in \[1e-06, 1e+06\] m" \
  ik --target 0.3 0 0 --upper 1e300 --fore 1e300 --json
expect_refused "--upper 9.99989e-321 must be a length in \[1e-06, 1e+06\] m" \
  ik --target 0.3 0 0 --upper 1e-320 --fore 1e-320 --json
expect_refused "--fore 1e-07 must be a length" ik --target 0.3 0 0 --fore 1e-7
"$conform" ik --target 0.3 0 0 --json > "$tmp/ik.json" || fail "a good ik was refused"
grep -q null "$tmp/ik.json" && fail "ik printed null"

# --- bounded outputs ------------------------------------------------------------------------------
mkdir "$tmp/frames"
expect_refused "--frames 2147483647 must be in \[1, 10000\]" \
  skin arm --frames 2147483647 --out "$tmp/frames/f.ply"
expect_refused "10000 frames of .* MiB would write .* MiB, more than --max-output-mib 1" \
  skin arm --frames 10000 --max-output-mib 1 --out "$tmp/frames/f.ply"
[[ -z "$(ls -A "$tmp/frames")" ]] || fail "a refused skin wrote frames"
expect_refused "key 'outputs.frames_every', value 1: with 20000 steps gives 20002 frames, more than the limit of 10000" \
  run arm-track --steps 20000 --set outputs.frames_every=1 --out "$tmp/out"
# With the ParaView series each frame is two files (PLY and .vtu): half as many frames fit.
expect_refused "key 'outputs.frames_every', value 1: with 6000 steps gives 12004 frame files (PLY and .vtu), more than the limit of 10000" \
  run arm-track --steps 6000 --set outputs.frames_every=1 --vtk --out "$tmp/out"
[[ ! -e "$tmp/out" ]] || fail "a refused run wrote its folder"

# --- events after the end, in every scene alike ---------------------------------------------------
expect_refused "key 'cut.at', value 0.3: the cut is after the last step: the scene ends at 0.0833333 s (5 steps of 0.0166667 s)" \
  run character --steps 5 --out "$tmp/out"
expect_refused "key 'tear.at', value 0.5: the tear's last sample (tear.at + tear.duration) at 0.9 s is after the last step" \
  run character --steps 40 --set cut.enabled=false --out "$tmp/out"
expect_refused "key 'drill.at', value 1.1: the drill is after the last step: the scene ends at 1 s" \
  run character --steps 60 --set cut.enabled=false --set tear.enabled=false --out "$tmp/out"
expect_refused "key 'cut.at', value 10.0: the cut is after the last step" run cut --steps 10 --set cut.at=10 --out "$tmp/out"
expect_refused "key 'drill.at', value 10.0: the drill is after the last step" run drill --steps 10 --set drill.at=10 --out "$tmp/out"
expect_refused "key 'slit.at', value 10.0: the slit is after the last step" run membrane-slit --steps 10 --set slit.at=10 --out "$tmp/out"
expect_refused "key 'cut.at', value 10.0: the cut is after the last step" run membrane-edge --steps 10 --set cut.at=10 --out "$tmp/out"
expect_refused "key 'tear.at', value 0.5: the tear's last sample (tear.at + tear.duration) at 1 s is after the last step" \
  run tear-opening --steps 30 --out "$tmp/out"
expect_refused "key 'pose.flex_at', value 1.5: the flex is after the last step" \
  run tear-opening --steps 70 --set pose.flex_deg=30 --out "$tmp/out"
echo "input_limits_test: ok"
