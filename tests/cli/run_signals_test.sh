#!/usr/bin/env bash
# SIGINT, SIGTERM and SIGHUP stop a run (scenes/base/interrupt.hpp), whether it is stepping or
# waiting for a helper (f3d, gnuplot, ffmpeg): it exits 128 + the signal, no process of it is
# left, its staging folder and lock are gone and the earlier result is untouched. A helper that
# fails is a failure of the run (exit 1, listed in summary.json), not a warning with exit 0.
set -euo pipefail
set -m  # each run in a process group of its own (to find its helpers), SIGINT not ignored
conform="$(realpath "$1")"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
fail() { echo "run_signals_test: $*" >&2; exit 1; }
for tool in f3d Xvfb gnuplot ffmpeg; do
  command -v "$tool" > /dev/null || { echo "run_signals_test: no $tool, skipped"; exit 77; }
done

# Stand-ins on PATH for the helpers: BLOCK=TOOL makes that one say so in $tmp/blocked and wait
# (a slow render, plot or video), FAIL=TOOL makes it fail; otherwise the real one runs. The f3d
# started early reads a FIFO (pictures/panels/last_K.ply): blocked or failing, it exits and its
# frame is rendered anew.
mkdir "$tmp/bin"
for tool in f3d gnuplot ffmpeg; do
  cat > "$tmp/bin/$tool" << EOF
#!/bin/sh
if [ "\$BLOCK" = $tool ] || [ "\$FAIL" = $tool ]; then
  case "\$*" in *panels/last_*) exit 3 ;; esac
  [ "\$FAIL" = $tool ] && exit 1
  echo $tool > "$tmp/blocked"
  exec sleep 300
fi
exec $(command -v "$tool") "\$@"
EOF
  chmod +x "$tmp/bin/$tool"
done

run() {  # run <env assignments...> -- <conform run args...>: in the background, $! its pid
  local envs=()
  while [[ "$1" != "--" ]]; do envs+=("$1"); shift; done
  shift
  env -u DISPLAY "${envs[@]}" PATH="$tmp/bin:$PATH" "$conform" run "$@" --set render.pictures=2 \
    > "$tmp/run.log" 2>&1 &
}

# The earlier result, which no stopped run may touch.
"$conform" run arm-track --steps 5 --no-render --set outputs.plots=false --out "$tmp/out" \
  > /dev/null 2>&1 || fail "the first run failed"
cp "$tmp/out/summary.json" "$tmp/earlier.json"

until_true() {  # until_true <tries of 0.1 s> <command...>
  local n="$1"; shift
  for ((i = 0; i < n; ++i)); do "$@" && return 0; sleep 0.1; done
  return 1
}
stepping() { [[ -d "$tmp/.out.staging-$1" ]] && pgrep -P "$1" -x Xvfb > /dev/null && pgrep -P "$1" -x f3d > /dev/null; }
gone() { ! kill -0 "$1" 2> /dev/null; }
group_empty() { ! pgrep -g "$1" > /dev/null; }

# stop_run <SIGNAL> <phase>: steps (the simulation, with Xvfb and the early f3d running), or the
# helper that is made to wait (f3d, gnuplot, ffmpeg).
stop_run() {
  local sig="$1" phase="$2" rc=0
  rm -f "$tmp/blocked"
  if [[ $phase == steps ]]; then
    run -- tear-opening --steps 100000 --out "$tmp/out"
  else
    run BLOCK="$phase" -- tear-opening --steps 60 --out "$tmp/out"
  fi
  local pid=$!
  if [[ $phase == steps ]]; then
    until_true 600 stepping "$pid" || fail "the run never got to stepping with its helpers"
  else
    until_true 600 test -e "$tmp/blocked" || { cat "$tmp/run.log" >&2; fail "$phase never ran"; }
  fi
  kill -s "$sig" "$pid"
  if ! until_true 600 gone "$pid"; then
    kill -s KILL -- "-$pid"
    wait "$pid" || true
    fail "SIG$sig while waiting for $phase did not stop the run within 60 s"
  fi
  wait "$pid" || rc=$?
  local expected=$((128 + $(kill -l "$sig")))
  [[ $rc -eq $expected ]] || { cat "$tmp/run.log" >&2; fail "SIG$sig during $phase: exit $rc, expected $expected"; }
  until_true 100 group_empty "$pid" || fail "SIG$sig during $phase left $(pgrep -g "$pid" -l | tr '\n' ' ')"
  cmp -s "$tmp/out/summary.json" "$tmp/earlier.json" || fail "SIG$sig during $phase changed the earlier result"
  [[ -z "$(find "$tmp" -maxdepth 1 -name '.out.staging-*')" ]] || fail "SIG$sig during $phase left its staging folder"
  [[ ! -e "$tmp/.out.lock" ]] || fail "SIG$sig during $phase left the lock file"
}

stop_run INT steps
stop_run TERM steps
stop_run HUP steps
stop_run INT f3d
stop_run TERM gnuplot
stop_run INT ffmpeg

# A helper that fails: the run is put in place with the failure recorded, and exits 1.
expect_failure() {  # expect_failure <tool> <summary pattern>
  local rc=0
  run FAIL="$1" -- tear-opening --steps 60 --out "$tmp/failed"
  wait $! || rc=$?
  [[ $rc -eq 1 ]] || { cat "$tmp/run.log" >&2; fail "a failing $1 gave exit $rc, expected 1"; }
  grep -q "$2" "$tmp/failed/summary.json" || fail "summary.json does not record that $1 failed"
  grep -q "the run is incomplete" "$tmp/run.log" || fail "no error said the run is incomplete"
}
expect_failure ffmpeg "ffmpeg failed"
[[ ! -e "$tmp/failed/run.gif" ]] || fail "a video after ffmpeg failed"
expect_failure f3d "2 of 2 renders are missing"
expect_failure gnuplot "not drawn: gnuplot failed"
echo "run_signals_test: ok"
