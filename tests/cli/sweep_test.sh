#!/usr/bin/env bash
# `conform sweep`, local path: a 2 x 3 grid gives 6 rows with the right values (checked against
# each run's own summary.json and against a separate `conform run` of one point), a rerun skips
# finished points, an injected failing point is reported while the others complete, the plots
# exist, --task/--gather run and collect points one by one, the job array file is well-formed,
# and bad grids are refused before anything runs.
# Usage: bash sweep_test.sh <conform> <source dir> <build dir>
set -euo pipefail
conform="$(realpath "$1")"
tmp="$(realpath "$(mktemp -d)")"
trap 'rm -rf "$tmp"' EXIT
fail() { echo "sweep_test: $*" >&2; exit 1; }
# A short arm-track: 20 steps at resolution 1, no frames (about 0.1 s a run).
short=(--steps 20 --set outputs.frames_every=0)

# --- 2 x 3 grid: 6 rows, each with its own values -------------------------------------------
"$conform" sweep arm-track --grid arm.kp=0.3,0.5 --grid physics.substeps=1,2,4 "${short[@]}" \
  --jobs 2 --out "$tmp/grid" > "$tmp/grid.log" 2>&1 || { cat "$tmp/grid.log" >&2; fail "grid sweep failed"; }
python3 - "$tmp/grid" <<'PY' || fail "grid table is wrong"
import csv, json, sys, itertools
d = sys.argv[1]
rows = list(csv.DictReader(open(d + "/sweep.csv")))
assert len(rows) == 6, f"{len(rows)} rows, not 6"
pairs = [(r["arm.kp"], r["physics.substeps"]) for r in rows]
assert pairs == list(itertools.product(["0.3", "0.5"], ["1", "2", "4"])), pairs
for r in rows:
    assert r["status"] == "ok" and r["exit_code"] == "0", r
    s = json.load(open(f"{d}/runs/{int(r['point']):05d}/summary.json"))
    # The run really used the row's values, and the row holds the run's metrics.
    assert s["settings"]["arm"]["kp"] == float(r["arm.kp"]), (s["settings"]["arm"], r)
    assert s["settings"]["physics"]["substeps"] == int(r["physics.substeps"])
    assert s["timings"]["steps"] == 20
    assert abs(float(r["metrics.rms_error"]) - s["metrics"]["rms_error"]) <= 1e-8 * s["metrics"]["rms_error"]
    assert float(r["metrics.with_gravity_compensation.max_error"]) > 0  # nested keys are flattened
    assert int(r["seed"]) == s["seed"] == 7
    assert float(r["run_wall_s"]) > 0 and float(r["timings.wall_s"]) > 0
# Different settings give different results (the values reached the runs).
assert len({r["metrics.rms_error"] for r in rows}) == 6
spec = json.load(open(d + "/sweep.json"))
assert [g["key"] for g in spec["grid"]] == ["arm.kp", "physics.substeps"]
assert spec["command"].startswith("conform sweep arm-track") and spec["version"]
assert len(spec["points"]) == 6
PY
# One point again, as a plain `conform run`: the same number as the sweep's row.
"$conform" run arm-track "${short[@]}" --set arm.kp=0.5 --set physics.substeps=2 \
  --out "$tmp/single" > /dev/null 2>&1 || fail "single run failed"
python3 - "$tmp" <<'PY' || fail "the sweep's row differs from a plain conform run"
import csv, json, sys
t = sys.argv[1]
row = [r for r in csv.DictReader(open(t + "/grid/sweep.csv")) if r["arm.kp"] == "0.5" and r["physics.substeps"] == "2"][0]
ref = json.load(open(t + "/single/summary.json"))["metrics"]["rms_error"]
assert abs(float(row["metrics.rms_error"]) - ref) <= 1e-8 * ref, (row["metrics.rms_error"], ref)
PY
# Plots: each headline metric (rms_error, max_error) against each numeric key.
for m in rms_error max_error; do
  for k in arm_kp physics_substeps; do
    png="$tmp/grid/plots/${m}_vs_${k}.png"
    [[ -s "$png" ]] || fail "no plot $png"
    [[ "$(head -c 8 "$png" | od -An -tx1 | tr -d ' \n')" == "89504e470d0a1a0a" ]] || fail "$png is not a PNG"
  done
done
# One line per value of the other key.
[[ $(grep -c "^     'data/\|^plot 'data/" "$tmp/grid/plots/rms_error_vs_physics_substeps.gp") -eq 2 ]] ||
  fail "rms_error vs substeps should have 2 lines (one per arm.kp)"
grep -q 'arm.kp = 0.3' "$tmp/grid/plots/rms_error_vs_physics_substeps.gp" || fail "no legend per line"
# A key of whole numbers gets a tic at each value (not 1.5 between 1 and 2); a key of fractions
# gnuplot's own tics.
grep -q '^set xtics (1, 2, 4)$' "$tmp/grid/plots/rms_error_vs_physics_substeps.gp" ||
  fail "substeps 1, 2, 4 should be the only x tics"
grep -q '^set xtics autofreq$' "$tmp/grid/plots/rms_error_vs_arm_kp.gp" || fail "arm.kp: gnuplot's tics"

# --- a rerun skips finished points ------------------------------------------------------------
stamp="$(stat -c %i-%Y "$tmp/grid/runs/00003/summary.json")"
rm -rf "$tmp/grid/runs/00004"  # one point lost: only it runs again
"$conform" sweep arm-track --grid arm.kp=0.3,0.5 --grid physics.substeps=1,2,4 "${short[@]}" \
  --out "$tmp/grid" > "$tmp/rerun.log" 2>&1 || { cat "$tmp/rerun.log" >&2; fail "rerun failed"; }
grep -q "5 of 6 points already finished, skipped" "$tmp/rerun.log" || { cat "$tmp/rerun.log" >&2; fail "rerun did not skip"; }
[[ $(grep -c "^sweep: point" "$tmp/rerun.log") -eq 1 ]] || fail "rerun ran more than the lost point"
[[ "$(stat -c %i-%Y "$tmp/grid/runs/00003/summary.json")" == "$stamp" ]] || fail "a finished point was rewritten"
[[ $(tail -n +2 "$tmp/grid/sweep.csv" | wc -l) -eq 6 ]] || fail "rerun table does not have 6 rows"
# A point whose summary is complete is done, exit 0, whatever an attempt that failed beside
# the run that finished it recorded (a resume beside a killed sweep's points wrote ok, exit 1).
echo '{"index": 2, "exit_code": 1, "error": "another run is writing it", "wall_s": 0.1}' \
  > "$tmp/grid/runs/00002.status.json"
"$conform" sweep --gather "$tmp/grid" > "$tmp/regather.log" 2>&1 || { cat "$tmp/regather.log" >&2; fail "gather of a done point with a failed record"; }
grep -q "6 of 6 points finished, 0 failed, 0 missing" "$tmp/regather.log" || { cat "$tmp/regather.log" >&2; fail "regather counts"; }
python3 - "$tmp/grid" <<'PY' || fail "a row's status does not match its exit code"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1] + "/sweep.csv")))
assert [(r["status"], r["exit_code"], r["error"]) for r in rows] == [("ok", "0", "")] * 6, rows
PY
# A different grid into the same folder is refused.
rc=0; "$conform" sweep arm-track --grid arm.kp=0.3 "${short[@]}" --out "$tmp/grid" 2> "$tmp/err" > /dev/null || rc=$?
[[ $rc -eq 2 ]] && grep -q "holds another sweep" "$tmp/err" || fail "another sweep into the same folder was not refused"

# --- an injected failing point: reported, the others complete ---------------------------------
# A cut scene of 10 steps (0.17 s) whose point 1 cuts at 1 s: it parses, and fails when it runs
# ("the event ... is after the last step", exit 1).
cut=(--steps 10 --set outputs.frames_every=0 --set outputs.plots=false)
rc=0
"$conform" sweep cut --grid cut.at=0.05,1.0,0.1 "${cut[@]}" --jobs 2 --out "$tmp/fail" \
  > "$tmp/fail.log" 2>&1 || rc=$?
[[ $rc -eq 1 ]] || { cat "$tmp/fail.log" >&2; fail "a sweep with a failed point should exit 1, not $rc"; }
grep -q "failed: point 1 (cut.at=1.0): exit 1: .*is after the last step" "$tmp/fail.log" ||
  { cat "$tmp/fail.log" >&2; fail "the failure is not reported with its error"; }
python3 - "$tmp/fail" <<'PY' || fail "failure table is wrong"
import csv, json, sys, os
d = sys.argv[1]
rows = list(csv.DictReader(open(d + "/sweep.csv")))
assert [r["status"] for r in rows] == ["ok", "failed", "ok"], [r["status"] for r in rows]
assert rows[1]["exit_code"] == "1" and "after the last step" in rows[1]["error"]
assert rows[1]["metrics.offset_max"] == "" and rows[1]["seed"] == "1"
assert all(float(rows[i]["metrics.offset_max"]) > 0 for i in (0, 2))
assert not os.path.exists(d + "/runs/00001")  # a failed run leaves no folder
status = json.load(open(d + "/runs/00001.status.json"))
assert status["exit_code"] == 1 and "after the last step" in status["error"]
assert "after the last step" in open(d + "/runs/00001.err").read()
PY
# A rerun retries the failed point only.
rc=0
"$conform" sweep cut --grid cut.at=0.05,1.0,0.1 "${cut[@]}" --out "$tmp/fail" > "$tmp/fail2.log" 2>&1 || rc=$?
[[ $rc -eq 1 ]] || fail "the rerun should fail again"
grep -q "2 of 3 points already finished" "$tmp/fail2.log" || { cat "$tmp/fail2.log" >&2; fail "the rerun did not skip the finished points"; }
grep -q "^sweep: point 1 (cut.at=1.0) FAILED" "$tmp/fail2.log" || fail "the rerun did not retry the failed point"

# --- --zip and --repeat -------------------------------------------------------------------------
"$conform" sweep arm-track --zip arm.kp=0.3,0.5 --zip physics.substeps=1,2 --repeat 2 "${short[@]}" \
  --plot rms_error,no_such_metric --out "$tmp/zip" > "$tmp/zip.log" 2>&1 || { cat "$tmp/zip.log" >&2; fail "zip sweep failed"; }
python3 - "$tmp/zip" <<'PY' || fail "zip/repeat table is wrong"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1] + "/sweep.csv")))
got = [(r["arm.kp"], r["physics.substeps"], r["repeat"], r["seed"]) for r in rows]
assert got == [("0.3", "1", "0", "1"), ("0.3", "1", "1", "2"), ("0.5", "2", "0", "1"), ("0.5", "2", "1", "2")], got
PY
[[ -s "$tmp/zip/plots/rms_error_vs_arm_kp.png" && ! -e "$tmp/zip/plots/max_error_vs_arm_kp.png" ]] ||
  fail "--plot rms_error should draw rms_error only"
# The zipped keys move together: one line of 2 points (the mean of 2 seeds each).
[[ $(ls "$tmp/zip/plots/data/rms_error_vs_arm_kp_"*.csv | wc -l) -eq 1 &&
   $(wc -l < "$tmp/zip/plots/data/rms_error_vs_arm_kp_0.csv") -eq 3 ]] || fail "zipped plot should be one line of 2 points"
python3 - "$tmp/zip" <<'PY' || fail "the plotted point is not the mean of the repeats"
import csv, sys
d = sys.argv[1]
rows = [r for r in csv.DictReader(open(d + "/sweep.csv")) if r["arm.kp"] == "0.3"]
pts = list(csv.DictReader(open(d + "/plots/data/rms_error_vs_arm_kp_0.csv")))
mean = sum(float(r["metrics.rms_error"]) for r in rows) / 2
assert abs(float(pts[0]["y"]) - mean) <= 1e-8 * mean, (pts, mean)
PY
grep -q "plot not drawn: no_such_metric: not a numeric metric of these runs (known: .*rms_error" "$tmp/zip.log" ||
  { cat "$tmp/zip.log" >&2; fail "a misspelt --plot metric is not reported"; }

# --- values reach gnuplot as text, never as commands -----------------------------------------
# A free-text key swept beside a numeric one: its values are the plot's line titles. Backquotes
# (a command inside a gnuplot double-quoted string), $(...), quotes, ';', '@' and a line break.
vals=$'description=a`touch BQ`;b@c,d$(touch DS)\nsystem "touch NL"\'q"'
"$conform" sweep arm-track --grid "$vals" --grid arm.kp=0.3,0.5 "${short[@]}" --plot rms_error \
  --out "$tmp/quote" > "$tmp/quote.log" 2>&1 || { cat "$tmp/quote.log" >&2; fail "the sweep of odd values failed"; }
[[ -z "$(find "$tmp" -name BQ -o -name DS -o -name NL)" ]] || fail "a sweep value ran as a command in gnuplot"
[[ -s "$tmp/quote/plots/rms_error_vs_arm_kp.png" ]] || { cat "$tmp/quote.log" >&2; fail "odd values kept the plot from being drawn"; }
! grep -q '[`$;@]' "$tmp/quote/plots/rms_error_vs_arm_kp.gp" || fail "a gnuplot script holds a raw \` \$ ; or @"
[[ $(grep -c "^     'data/\|^plot 'data/" "$tmp/quote/plots/rms_error_vs_arm_kp.gp") -eq 2 ]] ||
  fail "rms_error vs arm.kp should have 2 lines (one per description)"
# The values themselves reached the runs unchanged.
python3 - "$tmp/quote" <<'PY' || fail "odd values did not reach the runs"
import json, sys
d = sys.argv[1]
got = {json.load(open(f"{d}/runs/{i:05d}/summary.json"))["settings"]["description"] for i in range(4)}
assert got == {"a`touch BQ`;b@c", 'd$(touch DS)\nsystem "touch NL"\'q"'}, got
PY

# --- --slurm writes a well-formed job array; --task and --gather run it by hand ---------------
"$conform" sweep arm-track --grid arm.kp=0.3,0.5 --grid physics.substeps=1,2 "${short[@]}" \
  --slurm --partition debug --time 00:05:00 --array-limit 3 --sbatch-line --mem=2G \
  --sbatch-line '--account=my proj' --sbatch-line "-q low" --out "$tmp/task" > "$tmp/slurm.log" 2>&1 ||
  { cat "$tmp/slurm.log" >&2; fail "--slurm failed"; }
sb="$tmp/task/sweep.sbatch"
bash -n "$sb" || fail "sweep.sbatch is not valid bash"
[[ "$(head -1 "$sb")" == "#!/bin/bash" ]] || fail "sweep.sbatch has no shebang"
for line in "#SBATCH --array=0-3%3" "#SBATCH --partition=debug" "#SBATCH --time=00:05:00" \
            "#SBATCH --chdir=$tmp/task" "#SBATCH --output=$tmp/task/slurm/%A_%a.out" \
            "#SBATCH --mem=2G" "#SBATCH --account=my proj" "#SBATCH -q low"; do
  grep -qxF -- "$line" "$sb" || fail "sweep.sbatch lacks '$line'"
done
# Slurm stops reading #SBATCH lines at the first command.
awk '/^[^#]/ {cmd=1} /^#SBATCH/ && cmd {exit 1}' "$sb" || fail "an #SBATCH line follows a command"
grep -qxF "exec '$conform' sweep --task \"\$SLURM_ARRAY_TASK_ID\" '$tmp/task'" "$sb" || fail "the task line is wrong"
[[ ! -e "$tmp/task/runs/00000" ]] || fail "--slurm ran a point"
# Two of four tasks, as a scheduler would run them (the array's own command line).
for n in 0 3; do
  (cd / && SLURM_ARRAY_TASK_ID=$n bash -c "$(tail -1 "$sb")") > "$tmp/task$n.log" 2>&1 || fail "task $n failed"
done
rc=0; "$conform" sweep --gather "$tmp/task" > "$tmp/gather.log" 2>&1 || rc=$?
[[ $rc -eq 1 ]] || fail "gather with missing points should exit 1, not $rc"
grep -q "2 of 4 points finished, 0 failed, 2 missing" "$tmp/gather.log" || { cat "$tmp/gather.log" >&2; fail "gather count"; }
grep -q "missing: point 1 (arm.kp=0.3, physics.substeps=2)" "$tmp/gather.log" || fail "gather does not list the missing point"
grep -q "missing: point 2 (arm.kp=0.5, physics.substeps=1)" "$tmp/gather.log" || fail "gather does not list the missing point"
[[ $(tail -n +2 "$tmp/task/sweep.csv" | wc -l) -eq 2 ]] || fail "partial table should have 2 rows"
# It says how to run the missing points again: the array's tasks, or the sweep's own command.
grep -qxF "resubmit them: sbatch --array=1-2%3 '$tmp/task/sweep.sbatch'" "$tmp/gather.log" ||
  { cat "$tmp/gather.log" >&2; fail "gather does not print the sbatch command for the missing points"; }
grep -q "^conform sweep: 0 of 4 points failed, 2 missing" "$tmp/gather.log" || fail "no summary of the failure"
here="$(sed -n 's/^or run them here: //p' "$tmp/gather.log")"
[[ "$here" == "conform sweep arm-track --grid arm.kp=0.3,0.5 --grid physics.substeps=1,2 --set outputs.frames_every=0 --steps 20 --out $tmp/task" ]] ||
  fail "the local command is not the sweep's: $here"
"$conform" sweep --task 1 "$tmp/task" > /dev/null 2>&1 || fail "task 1 failed"
# The printed command, pasted into a shell in another folder, runs what is left (point 2).
mkdir -p "$tmp/bin" && ln -sf "$conform" "$tmp/bin/conform"
(cd / && PATH="$tmp/bin:$PATH" bash -c "$here") > "$tmp/here.log" 2>&1 || { cat "$tmp/here.log" >&2; fail "the printed command failed"; }
grep -q "3 of 4 points already finished" "$tmp/here.log" || { cat "$tmp/here.log" >&2; fail "the printed command did not resume"; }
"$conform" sweep --task 0 "$tmp/task" > "$tmp/again.log" 2>&1 || fail "a finished task should succeed"
grep -q "already finished" "$tmp/again.log" || fail "a finished task ran again"
"$conform" sweep --gather "$tmp/task" > "$tmp/gather2.log" 2>&1 || { cat "$tmp/gather2.log" >&2; fail "full gather failed"; }
# The tasks' table equals the local pool's for the same points (metrics are deterministic).
python3 - "$tmp" <<'PY' || fail "task table differs from the local one"
import csv, sys
t = sys.argv[1]
key = lambda r: (r["arm.kp"], r["physics.substeps"])
local = {key(r): r for r in csv.DictReader(open(t + "/grid/sweep.csv"))}
tasks = list(csv.DictReader(open(t + "/task/sweep.csv")))
assert len(tasks) == 4
for r in tasks:
    assert r["metrics.rms_error"] == local[key(r)]["metrics.rms_error"], (r, local[key(r)])
PY

# --- a scene file named by a relative path: the tasks find it from any folder ------------------
"$conform" scenes --show arm-track > "$tmp/my-arm.json"
(cd "$tmp" && "$conform" sweep my-arm.json --grid arm.kp=0.3,0.5 "${short[@]}" --slurm --out file) > /dev/null 2>&1 ||
  fail "a sweep of a scene file failed"
grep -q "\"scene\": \"$tmp/my-arm.json\"" "$tmp/file/sweep.json" || fail "the scene file is not kept by its absolute path"
(cd / && "$conform" sweep --task 1 "$tmp/file") > /dev/null 2>&1 || fail "a task of a scene-file sweep failed"
[[ -s "$tmp/file/runs/00001/summary.json" ]] || fail "the scene-file task wrote no summary"

# --- bad grids are refused before anything runs (the --set validation) -------------------------
expect_refused() {  # expect_refused <stderr pattern> <args...>
  local pattern="$1"; shift
  rm -rf "$tmp/bad"; local rc=0
  "$conform" sweep arm-track "$@" --out "$tmp/bad" > /dev/null 2> "$tmp/err" || rc=$?
  [[ $rc -eq 2 ]] || fail "sweep $* should exit 2, not $rc"
  grep -q -- "$pattern" "$tmp/err" || { cat "$tmp/err" >&2; fail "sweep $*: no '$pattern'"; }
  [[ ! -e "$tmp/bad" ]] || fail "sweep $* wrote $tmp/bad"
}
expect_refused "key 'physics.dtt', value 0.01: unknown key" --grid physics.dtt=0.01,0.02
expect_refused "key 'physics.dt', value -1: must be in \[1e-05, 0.1\] (point 1: physics.dt=-1)" --grid physics.dt=0.01,-1
expect_refused "key 'arm.gravity_compensation', value \"sometimes\": must be one of" --grid arm.gravity_compensation=both,sometimes
expect_refused "key 'targets.center', value \[1\]: must be an array of 3 numbers" --grid 'targets.center=[0,-0.25,0.3],[1]'
expect_refused "--grid needs KEY=V1,V2" --grid arm.kp
expect_refused "lists this value twice" --grid arm.kp=0.3,0.3
expect_refused "is swept twice" --grid arm.kp=0.3 --grid arm.kp=0.5
expect_refused "--zip axes must have the same length" --zip arm.kp=0.3,0.5 --zip physics.substeps=1,2,3
expect_refused "cannot be swept with --repeat" --grid seed=1,2 --repeat 2
expect_refused "key '--time', value \"10 minutes\": must be one word" --grid arm.kp=0.3 --slurm --time "10 minutes"
expect_refused "key '--time', value 1:2:3:4: is not a Slurm time" --grid arm.kp=0.3 --slurm --time 1:2:3:4
# An #SBATCH line is one line (a line break would start a command of the script), an option,
# and not the array.
expect_refused "key '--sbatch-line', value \"--mem=1G\\\\ntouch /tmp/x\": must be one line" --grid arm.kp=0.3 --slurm \
  --sbatch-line $'--mem=1G\ntouch /tmp/x'
expect_refused "key '--sbatch-line', value \"--mem=1G\\\\r\": must be one line" --grid arm.kp=0.3 --slurm --sbatch-line $'--mem=1G\r'
expect_refused "key '--sbatch-line', value \"mem=4G\": must be an sbatch option" --grid arm.kp=0.3 --slurm --sbatch-line mem=4G
expect_refused "value \"--array=0-9\": the array is the sweep's points" --grid arm.kp=0.3 --slurm --sbatch-line --array=0-9
expect_refused "value \"-a 0-9\": the array is the sweep's points" --grid arm.kp=0.3 --slurm --sbatch-line "-a 0-9"
expect_refused "key '--sbatch-line', value \"--mem=1G\": needs --slurm or --submit" --grid arm.kp=0.3 --sbatch-line --mem=1G
rc=0; "$conform" sweep --task 9 "$tmp/task" 2> "$tmp/err" || rc=$?
[[ $rc -eq 2 ]] && grep -q "is not a point of this sweep (0..3)" "$tmp/err" || fail "--task 9 was not refused"
rc=0; "$conform" sweep --gather "$tmp/task" --grid arm.kp=1 2> "$tmp/err" || rc=$?
[[ $rc -eq 2 ]] && grep -q "takes only the sweep folder" "$tmp/err" || fail "--gather with a grid was not refused"
rc=0; "$conform" sweep --gather "$tmp/nothing" 2> "$tmp/err" || rc=$?
[[ $rc -eq 2 ]] && grep -q "sweep.json: cannot read" "$tmp/err" || fail "--gather of a non-sweep was not refused"
echo "sweep_test: ok"
