#!/usr/bin/env bash
# The command's basic contract: --version, info, and a clear non-zero exit on bad usage.
set -euo pipefail
conform="$1"
"$conform" --version | grep -q "conform "
"$conform" info | grep -q "Bullet precision"
if "$conform" no-such-command >/dev/null 2>&1; then
  echo "cli_test: an unknown subcommand must fail" >&2
  exit 1
fi
# Bad numbers and sizes: a clear error and an exit code below 128, nothing written.
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
expect_refused() {  # expect_refused <stderr pattern> <args...>
  local pattern="$1" rc=0; shift
  "$conform" "$@" > "$tmp/stdout" 2> "$tmp/stderr" || rc=$?
  if [[ $rc -eq 0 || $rc -ge 128 ]] || ! grep -q -- "$pattern" "$tmp/stderr"; then
    cat "$tmp/stderr" >&2
    echo "cli_test: $* gave rc $rc, expected an error with '$pattern'" >&2
    exit 1
  fi
}
expect_refused "must be a finite number, not nan" skin arm --time nan --out "$tmp/nan.ply"
[[ ! -e "$tmp/nan.ply" ]] || { echo "cli_test: skin --time nan wrote a file" >&2; exit 1; }
expect_refused "must be a finite number, not inf" ik --target 0.1 inf 0.2
expect_refused "must be a finite number, not 1e400" cut arm --plane 0 0 1 1e400 --out "$tmp/big.ply"
# arm:N grows as N^2 (arm:50 peaked at 4.2 GB): N is capped at 32, said in the error.
expect_refused "resolution must be an integer in .1, 32." info arm:33
echo "cli_test: ok"
