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
echo "cli_test: ok"
