#!/usr/bin/env bash
# `conform run` / `conform scenes` contract: the list, errors that name key, value and reason
# with nothing written, the files a run writes, and identical numbers for the same seed.
# Usage: bash run_scenes_test.sh <conform> <source dir> <build dir>
set -euo pipefail
conform="$(realpath "$1")"
tmp="$(realpath "$(mktemp -d)")"
trap 'rm -rf "$tmp"' EXIT
fail() { echo "run_scenes_test: $*" >&2; exit 1; }

# The list: one line per built-in scene, each runnable.
"$conform" scenes > "$tmp/list"
grep -q "^arm-track " "$tmp/list" || fail "scenes does not list arm-track"
"$conform" scenes --show arm-track > "$tmp/arm.json"
grep -q '"scene": "arm-track"' "$tmp/arm.json" || fail "--show does not print the scene file"

# Bad keys and values: exit code 2, the key, value and reason on stderr, no folder.
expect_error() {  # expect_error <stderr pattern> <args...>
  local pattern="$1"; shift
  local out="$tmp/bad"
  rm -rf "$out"
  local rc=0
  "$conform" run "$@" --out "$out" > "$tmp/stdout" 2> "$tmp/stderr" || rc=$?
  [[ $rc -ne 0 ]] || fail "run $* should fail"
  [[ $rc -lt 128 ]] || fail "run $* died of a signal (rc $rc) instead of an error"
  grep -q -- "$pattern" "$tmp/stderr" || { cat "$tmp/stderr" >&2; fail "run $*: no '$pattern' in the error"; }
  [[ ! -e "$out" ]] || fail "run $* wrote $out despite the error"
}
expect_error "key 'physics.dtt', value 0.01: unknown key" arm-track --set physics.dtt=0.01
expect_error "key 'physics.dt', value -1: must be in \[1e-05, 0.1\]" arm-track --set physics.dt=-1
expect_error "key 'arm.gravity_compensation', value \"sometimes\": must be one of" \
  arm-track --set arm.gravity_compensation=sometimes
expect_error "key 'targets.center', value \[1\]: must be an array of 3 numbers" \
  arm-track --set 'targets.center=[1]'
expect_error "key 'scene', value \"no-such-kind\": unknown scene kind" \
  arm-track --set scene=no-such-kind
expect_error "neither a built-in scene" no-such-scene
printf '{ "scene": "arm-track", ' > "$tmp/broken.json"
expect_error "not valid JSON" "$tmp/broken.json"
printf '{ "scene": "arm-track", "seed": "seven" }' > "$tmp/badseed.json"
expect_error "key 'seed', value \"seven\": must be an integer" "$tmp/badseed.json"
# A value nested 100,000 deep: printing it for the error overflowed the stack (rc 139).
python3 -c 'print("{\"scene\": \"arm-track\", \"seed\": " + "[" * 100000 + "]" * 100000 + "}")' \
  > "$tmp/deep.json"
expect_error "key 'seed', value \[\[\[\[\[\[\[\[\[...\]\]\]\]\]\]\]\]\]: must be an integer" "$tmp/deep.json"

# 2^32 steps (42949.67296 s / 1e-5 s) wrapped to a 1-step run that exited 0.
expect_error "key 'duration', value 42949.67296: with physics.dt = 1e-05 gives 4294967296 steps, more than the limit of 100000000" \
  arm-track --set duration=42949.67296 --set physics.dt=1e-5
# A finite but huge gravity made the results non-finite, with exit 0.
expect_error "key 'physics.gravity', value \[0,-1e+300,0\]: its length must be at most 1000" \
  arm-track --set 'physics.gravity=[0,-1e300,0]'

# A short run from a scene file: every output, and the same numbers twice.
cp "$tmp/arm.json" "$tmp/my-arm.json"
for run in a b; do
  "$conform" run "$tmp/my-arm.json" --steps 90 --set outputs.frames_every=30 \
    --set model.resolution=1 --out "$tmp/$run" > "$tmp/$run.log" 2>&1 ||
    { cat "$tmp/$run.log" >&2; fail "run $run failed"; }
done
for f in metrics.csv summary.json frames/arm_000000.ply frames/arm_000030.ply \
         frames/arm_000090.ply; do
  [[ -s "$tmp/a/$f" ]] || fail "missing $f"
done
[[ $(wc -l < "$tmp/a/metrics.csv") -eq 91 ]] || fail "metrics.csv should have a header and 90 rows"
cmp -s "$tmp/a/metrics.csv" "$tmp/b/metrics.csv" || fail "the same seed gave different metrics"
for key in '"rms_error"' '"max_error"' '"steady_state_error"' '"ik_ns_per_solve"' \
           '"wall_per_simulated_second_s"' '"wall_per_step_ms"' '"version"' '"settings"'; do
  grep -q "$key" "$tmp/a/summary.json" || fail "summary.json has no $key"
done
grep -q "results in" "$tmp/a.log" || fail "run does not say where the results went"
if command -v gnuplot > /dev/null; then
  for png in tracking_error.png trajectory.png; do
    [[ -s "$tmp/a/$png" ]] || fail "missing plot $png"
    head -c 8 "$tmp/a/$png" | grep -q PNG || fail "$png is not a PNG"
  done
fi
# The soft-body scenes are deterministic too (Bullet is single-threaded here).
for run in e f; do
  "$conform" run tear-opening --steps 70 --set outputs.plots=false --out "$tmp/$run" \
    > /dev/null 2>&1 || fail "tear-opening run $run failed"
done
cmp -s "$tmp/e/metrics.csv" "$tmp/f/metrics.csv" || fail "tear-opening is not deterministic"
cmp -s "$tmp/e/profile_history.csv" "$tmp/f/profile_history.csv" ||
  fail "tear-opening profiles are not deterministic"
# A different seed gives different random waypoints.
"$conform" run arm-track --steps 700 --set seed=8 --set outputs.plots=false --out "$tmp/c" \
  > /dev/null 2>&1 || fail "run with seed 8 failed"
"$conform" run arm-track --steps 700 --set outputs.plots=false --out "$tmp/d" > /dev/null 2>&1 ||
  fail "run with seed 7 failed"
cmp -s "$tmp/c/metrics.csv" "$tmp/d/metrics.csv" && fail "seeds 7 and 8 gave the same run"
# The main job: `conform` alone runs the default scene and says where the results went.
mkdir -p "$tmp/default"
(cd "$tmp/default" && "$conform" > out.log 2>&1) || { cat "$tmp/default/out.log" >&2; fail "conform alone failed"; }
grep -q "running the default scene 'tear-opening'" "$tmp/default/out.log" || fail "no default-scene notice"
grep -q "results in $tmp/default/results/tear-opening/" "$tmp/default/out.log" ||
  fail "conform alone does not say where the results went"
for f in summary.json metrics.csv profiles.csv profile_history.csv; do
  [[ -s "$tmp/default/results/tear-opening/$f" ]] || fail "default run: missing $f"
done
for key in '"max_opening"' '"profile_r2"' '"opened_area"'; do
  grep -q "$key" "$tmp/default/results/tear-opening/summary.json" || fail "default run: no $key"
done
# Every built-in scene is listed.
for s in tear-opening arm-track cut drill character; do
  grep -q "^$s " "$tmp/list" || fail "scenes does not list $s"
done
echo "run_scenes_test: ok"
