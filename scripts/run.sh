#!/usr/bin/env bash
# Builds everything and runs the main job: `conform` with its default scene.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/build.sh"
build="${CONFORM_BUILD_DIR:-$root/build}"
exec "$build/scenes/conform" "$@"
