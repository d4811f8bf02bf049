#!/usr/bin/env bash
# Installs what `conform` needs (scripts/deps.sh run), builds only the command and runs it:
# with no arguments, the default scene. Arguments go to conform (`scripts/run.sh run cut`).
# scripts/build.sh (or scripts/test.sh) builds everything else: tests, benchmarks, Python.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/build.sh" --profile run
build="${CONFORM_BUILD_DIR:-$root/build}"
exec "$build/scenes/conform" "$@"
