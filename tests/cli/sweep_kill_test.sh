#!/usr/bin/env bash
# `conform sweep` and its point runs: SIGTERM, SIGINT and SIGHUP stop the sweep, which stops
# its running points, waits for them and exits 128 + the signal; SIGKILL of the sweep kills
# its points too (the kernel's parent-death signal). A second sweep (or --gather) into a
# folder whose sweep still runs is refused at once, and a resume right after a kill either is
# refused the same way or runs the stopped points, never beside them.
# Usage: bash sweep_kill_test.sh <conform> <source dir> <build dir>
set -euo pipefail
conform="$(realpath "$1")"
tmp="$(realpath "$(mktemp -d)")"
started=()  # every point run this test saw, killed at exit if one is left (by its pid)
cleanup() {
  for pid in "${started[@]}"; do kill -KILL "$pid" 2> /dev/null || true; done
  rm -rf "$tmp"
}
trap cleanup EXIT
fail() { echo "sweep_kill_test: $*" >&2; exit 1; }
# Job control: a background job then gets SIGINT as a foreground one would (bash otherwise
# starts it with SIGINT ignored), in a process group of its own.
set -m
# Points that run for hours (10^7 steps of arm-track, about 0.5 ms each) unless stopped.
long=(--steps 10000000 --set outputs.frames_every=0 --set outputs.metrics_every=100
      --set outputs.plots=false)

# children <pid>: the pids of its child processes.
children() { cat /proc/"$1"/task/*/children 2> /dev/null | tr ' ' '\n' | grep . || true; }
# wait_points <sweep pid> <n>: waits (up to 60 s) until the sweep runs n points; prints their pids.
wait_points() {
  local pids="" end=$((SECONDS + 60))
  while [[ $SECONDS -lt $end ]]; do
    pids="$(children "$1")"
    [[ $(grep -c . <<< "$pids") -ge $2 ]] && { echo "$pids"; return; }
    kill -0 "$1" 2> /dev/null || break
    sleep 0.1
  done
  fail "the sweep did not start $2 points"
}
# gone <pid...>: waits (up to 20 s) until none of the processes lives; fails otherwise.
gone() {
  local end=$((SECONDS + 20))
  while [[ $SECONDS -lt $end ]]; do
    local alive=0
    for pid in "$@"; do
      [[ -e /proc/$pid && "$(awk '{print $3}' /proc/"$pid"/stat 2> /dev/null)" != Z ]] && alive=1
    done
    [[ $alive -eq 0 ]] && return
    sleep 0.1
  done
  fail "point runs $* outlived their sweep"
}

# --- TERM, INT, HUP: the points are stopped and waited for, the exit code is 128 + signal ---
for sig in TERM INT HUP; do
  dir="$tmp/$sig"
  "$conform" sweep arm-track --grid arm.kp=0.3,0.5 "${long[@]}" --jobs 2 --out "$dir" \
    > "$tmp/$sig.log" 2>&1 &
  sweep=$!
  pids="$(wait_points "$sweep" 2)"; read -ra points <<< "$(echo $pids)"
  started+=("${points[@]}")
  kill -s "$sig" "$sweep"
  rc=0; wait "$sweep" || rc=$?
  case $sig in TERM) want=143 ;; INT) want=130 ;; HUP) want=129 ;; esac
  [[ $rc -eq $want ]] || { cat "$tmp/$sig.log" >&2; fail "SIG$sig: the sweep exited $rc, not $want"; }
  gone "${points[@]}"
  grep -q "SIG$sig: stopping 2 running points" "$tmp/$sig.log" ||
    { cat "$tmp/$sig.log" >&2; fail "SIG$sig: no word of the stopped points"; }
  # The stopped points are missing (to be resumed), not failed.
  [[ ! -e "$dir/runs/00000.status.json" && ! -e "$dir/runs/00001.status.json" ]] ||
    fail "SIG$sig: a stopped point was recorded as a failure"
done

# --- KILL: the kernel stops the points -------------------------------------------------------
"$conform" sweep arm-track --grid arm.kp=0.3,0.5 "${long[@]}" --jobs 2 --out "$tmp/kill" \
  > "$tmp/kill.log" 2>&1 &
sweep=$!
pids="$(wait_points "$sweep" 2)"; read -ra points <<< "$(echo $pids)"
started+=("${points[@]}")
kill -KILL "$sweep"
{ wait "$sweep"; } 2> /dev/null || true
gone "${points[@]}"

# --- one sweep per folder ----------------------------------------------------------------------
"$conform" sweep arm-track --grid arm.kp=0.3,0.5 "${long[@]}" --jobs 2 --out "$tmp/lock" \
  > "$tmp/lock.log" 2>&1 &
sweep=$!
pids="$(wait_points "$sweep" 2)"; read -ra points <<< "$(echo $pids)"
started+=("${points[@]}")
rc=0
"$conform" sweep arm-track --grid arm.kp=0.3,0.5 "${long[@]}" --jobs 2 --out "$tmp/lock" \
  > "$tmp/second.log" 2> "$tmp/second.err" &
second=$!
# The second sweep must not start a point; it ends by itself (refused).
end=$((SECONDS + 60))
while [[ $SECONDS -lt $end ]] && kill -0 "$second" 2> /dev/null; do sleep 0.1; done
started+=($(children "$second"))
kill -0 "$second" 2> /dev/null && { kill -TERM "$second"; fail "the second sweep did not stop by itself"; }
wait "$second" || rc=$?
[[ $rc -eq 2 ]] || { cat "$tmp/second.log" "$tmp/second.err" >&2; fail "a second sweep into a running one exited $rc, not 2"; }
grep -q "another sweep is running in $tmp/lock" "$tmp/second.err" ||
  { cat "$tmp/second.err" >&2; fail "the refusal does not say why"; }
[[ ! -s "$tmp/second.log" ]] || { cat "$tmp/second.log" >&2; fail "the refused sweep printed progress"; }
rc=0; "$conform" sweep --gather "$tmp/lock" > /dev/null 2> "$tmp/gather.err" || rc=$?
[[ $rc -eq 2 ]] && grep -q "another sweep is running" "$tmp/gather.err" ||
  fail "--gather of a running sweep should be refused (exit $rc)"
# Its point runs are those of the first sweep only, still running.
[[ $(children "$sweep" | grep -c .) -eq 2 ]] || fail "the first sweep lost its points"
kill -TERM "$sweep"
{ wait "$sweep"; } 2> /dev/null || true
gone "${points[@]}"

# --- a resume right after SIGKILL -------------------------------------------------------------
# Points of a second or two each: the killed sweep's points would still be running when the
# resume starts, if they outlived it.
mid=(--steps 3000 --set outputs.frames_every=0 --set outputs.plots=false)
"$conform" sweep arm-track --grid arm.kp=0.3,0.5 "${mid[@]}" --jobs 2 --out "$tmp/resume" \
  > "$tmp/resume0.log" 2>&1 &
sweep=$!
pids="$(wait_points "$sweep" 2)"; read -ra points <<< "$(echo $pids)"
started+=("${points[@]}")
kill -KILL "$sweep"
{ wait "$sweep"; } 2> /dev/null || true
rc=0
"$conform" sweep arm-track --grid arm.kp=0.3,0.5 "${mid[@]}" --jobs 2 --out "$tmp/resume" \
  > "$tmp/resume1.log" 2>&1 || rc=$?
if [[ $rc -eq 2 ]]; then
  # Refused while the killed points end; once they have, the resume runs.
  grep -q "another sweep is running" "$tmp/resume1.log" || { cat "$tmp/resume1.log" >&2; fail "resume refused without the reason"; }
  gone "${points[@]}"
  rc=0
  "$conform" sweep arm-track --grid arm.kp=0.3,0.5 "${mid[@]}" --jobs 2 --out "$tmp/resume" \
    > "$tmp/resume1.log" 2>&1 || rc=$?
fi
[[ $rc -eq 0 ]] || { cat "$tmp/resume1.log" >&2; fail "the resume after a kill exited $rc"; }
! grep -q "FAILED\|another run is writing" "$tmp/resume1.log" ||
  { cat "$tmp/resume1.log" >&2; fail "the resume ran beside the killed sweep's points"; }
grep -q "2 of 2 points finished, 0 failed, 0 missing" "$tmp/resume1.log" ||
  { cat "$tmp/resume1.log" >&2; fail "the resume's counts"; }
python3 - "$tmp/resume" <<'PY' || fail "the resumed table is wrong"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1] + "/sweep.csv")))
assert [(r["status"], r["exit_code"]) for r in rows] == [("ok", "0")] * 2, rows
PY
echo "sweep_kill_test: ok"
