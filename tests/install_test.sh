#!/usr/bin/env bash
# Installs the built project into a temporary prefix, builds tests/consumer against it with
# find_package(Conform) and runs it. Arguments: <conform binary> <source dir> <build dir>.
set -euo pipefail
source_dir="$2"
build_dir="$3"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cmake --install "$build_dir" --prefix "$work/prefix" >/dev/null
double="$(grep -E '^CONFORM_DOUBLE:BOOL=' "$build_dir/CMakeCache.txt" | cut -d= -f2)"
cmake -S "$source_dir/tests/consumer" -B "$work/build" -DCMAKE_PREFIX_PATH="$work/prefix" \
  -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$work/build" >/dev/null
"$work/build/consumer"
echo "install_test: find_package(Conform) from $work/prefix works (CONFORM_DOUBLE=$double)"
