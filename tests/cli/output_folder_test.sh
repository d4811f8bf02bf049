#!/usr/bin/env bash
# --out is the user's folder (scenes/base/output_folder.hpp): a run replaces only an earlier Conform
# result; it refuses (exit 2, nothing touched) the current folder, its ancestors, the folder of
# an input and any other folder of files; it removes its lock when it ends and the staging
# folders of killed runs. And no --out or scene name reaches a shell or gnuplot's command
# substitution: helpers run from argument vectors.
set -euo pipefail
conform="$(realpath "$1")"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
fail() { echo "output_folder_test: $*" >&2; exit 1; }

# A closed cube: a model any command can cut.
cube() {
  printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n' > "$1"
  printf 'f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n' >> "$1"
}
# A listing of every file under a folder with its checksum, to compare before and after.
snapshot() { (cd "$1" && find . -type f -print0 | sort -z | xargs -0 -r sha1sum; find . | sort); }

# expect_refused <folder to run in> <stderr pattern> <conform args...>: exit 2, the reason on
# stderr, and the folder tree around it (the run folder's parent) unchanged.
expect_refused() {
  local where="$1" pattern="$2" rc=0; shift 2
  local before; before="$(snapshot "$tmp")"
  (cd "$where" && "$conform" "$@") > "$tmp.stdout" 2> "$tmp.stderr" || rc=$?
  [[ $rc -eq 2 ]] || { cat "$tmp.stderr" >&2; fail "$* in $where: exit $rc, expected 2"; }
  grep -q -- "$pattern" "$tmp.stderr" || { cat "$tmp.stderr" >&2; fail "$*: no '$pattern'"; }
  [[ "$(snapshot "$tmp")" == "$before" ]] || fail "$* in $where changed files"
}

# The reproducers: `cut cube.obj --out .` deleted cube.obj and its folder's files, `--out ..`
# the parent's, `run arm-track --out .` the folder's, before failing.
mkdir -p "$tmp/work/sub"
cube "$tmp/work/cube.obj"
echo "mine" > "$tmp/work/notes.txt"
echo "mine too" > "$tmp/work/sub/data.csv"
expect_refused "$tmp/work" "is the current folder" cut cube.obj --plane 0 0 1 0.5 --out .
expect_refused "$tmp/work" "is the current folder" cut cube.obj --plane 0 0 1 0.5 --out "$tmp/work/"
expect_refused "$tmp/work/sub" "is an ancestor of the current folder" \
  cut ../cube.obj --plane 0 0 1 0.5 --out ..
expect_refused "$tmp/work/sub" "is an ancestor of the current folder" run arm-track --out "$tmp"
expect_refused "$tmp/work/sub" "is the current folder" run arm-track --steps 5 --out .
# The folder of an input (here with nothing else in it) and a folder of other files.
mkdir -p "$tmp/models"
cube "$tmp/models/cube.obj"
expect_refused "$tmp" "holds the input" cut models/cube.obj --plane 0 0 1 0.5 --out models
printf 't,ax,ay,az,bx,by,bz\n0,0,0,0.1,0.2,0.03,0.1\n1,0,0,0.2,0.2,0.03,0.2\n' > "$tmp/models/s.csv"
expect_refused "$tmp" "holds the input" tear arm --scalpel models/s.csv --out models
expect_refused "$tmp" "not an earlier Conform result" cut work/cube.obj --plane 0 0 1 0.5 --out work/sub
expect_refused "$tmp/work" "not an earlier Conform result" run arm-track --steps 5 --out "$tmp/work/sub"

# A result holds its marker; the next run replaces it, and no lock file is left behind.
(cd "$tmp" && "$conform" cut work/cube.obj --plane 0 0 1 0.5 --out res > /dev/null 2>&1) ||
  fail "cut into a new folder failed"
[[ -f "$tmp/res/.conform-run" ]] || fail "no .conform-run marker in the result"
[[ ! -e "$tmp/.res.lock" ]] || fail "the lock file stayed after the run"
echo stale > "$tmp/res/stale.txt"
# Staging folders of dead runs go; one whose pid lives (this shell's) stays.
sh -c 'exit 0' & dead=$!
wait "$dead"
mkdir -p "$tmp/.res.staging-$dead" "$tmp/.res.staging-$$"
echo x > "$tmp/.res.staging-$dead/piece_000.ply"
(cd "$tmp" && "$conform" cut work/cube.obj --plane 0 0 1 0.25 --out res > /dev/null 2>&1) ||
  fail "a second cut into the result failed"
[[ ! -e "$tmp/res/stale.txt" ]] || fail "the earlier result's file stayed"
[[ ! -e "$tmp/.res.staging-$dead" ]] || fail "the dead run's staging folder stayed"
[[ -d "$tmp/.res.staging-$$" ]] || fail "a live process's staging folder was removed"
rmdir "$tmp/.res.staging-$$"
[[ ! -e "$tmp/.res.lock" ]] || fail "the lock file stayed after the second run"
# A failed run leaves no lock either.
rc=0
(cd "$tmp" && "$conform" drill work/cube.obj --tip 5 5 5 --base 5 5 6 --radius 0.01 --out res \
  > /dev/null 2>&1) || rc=$?
[[ $rc -eq 1 ]] || fail "a drill that misses exited $rc"
[[ ! -e "$tmp/.res.lock" ]] || fail "the lock file stayed after a failed run"
[[ -f "$tmp/res/piece_000.ply" ]] || fail "a failed run touched the earlier result"

# Shell and gnuplot syntax in --out and in the scene's name (a scene file's stem, which titles
# the pictures): nothing runs, and the run with its plots, pictures and video still works.
weird=$'r$(touch SENT1)`touch SENT2`q\'u"o;touch SENT3;\nl'
mkdir -p "$tmp/inj"
"$conform" scenes --show tear-opening > "$tmp/inj/${weird}.json"
rc=0
(cd "$tmp/inj" && env -u DISPLAY "$conform" run "${weird}.json" --steps 60 \
  --set render.pictures=2 --set render.video=gif --out "$weird" > ../inj.log 2>&1) || rc=$?
for s in SENT1 SENT2 SENT3; do
  [[ ! -e "$tmp/inj/$s" && ! -e "$tmp/inj/$weird/$s" && ! -e "$tmp/$s" ]] ||
    fail "a command in the folder's name ran ($s)"
done
[[ $rc -eq 0 ]] || { cat "$tmp/inj.log" >&2; fail "the run into an odd folder name exited $rc"; }
out="$tmp/inj/$weird"
grep -q '"failures": \[\]' "$out/summary.json" || fail "the run recorded failures"
if command -v gnuplot > /dev/null; then
  ls "$out"/*.png > /dev/null 2>&1 || fail "no plot drawn into an odd folder name"
fi
if command -v f3d > /dev/null && command -v Xvfb > /dev/null; then
  [[ -f "$out/pictures/step_000060.png" ]] || fail "no picture rendered into an odd folder name"
  command -v ffmpeg > /dev/null && { [[ -f "$out/run.gif" ]] || fail "no video"; }
  # render.sh, the record of the renders, is safe to run too (here with an f3d that does nothing).
  mkdir -p "$tmp/bin" && printf '#!/bin/sh\nexit 0\n' > "$tmp/bin/f3d" && chmod +x "$tmp/bin/f3d"
  (cd "$out/pictures" && PATH="$tmp/bin:$PATH" sh render.sh) > /dev/null 2>&1 ||
    fail "render.sh failed"
  [[ -z "$(find "$tmp" -name 'SENT*')" ]] || fail "running render.sh ran a command of the name"
fi
echo "output_folder_test: ok"
