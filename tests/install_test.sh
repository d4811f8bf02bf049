#!/usr/bin/env bash
# Installs the built project into a temporary prefix, builds tests/consumer against it with
# find_package(Conform) and runs it. Checks what an application gets from the package: the
# Bullet consumer (conform::core, conform::bullet) compiles without -fopenmp or any Conform
# definition and links no assimp; the importer (conform::io) links assimp and reads a model;
# the headers installed are exactly the API's list (tests/installed_headers.txt);
# the application (tests/consumer/application.cpp) runs, also built with ASan and UBSan; a
# project of the other Bullet precision fails at configure time with a message.
# Arguments: <conform binary> <source dir> <build dir>.
set -euo pipefail
source_dir="$2"
build_dir="$3"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
fail() {
  echo "install_test: $*" >&2
  exit 1
}
cmake --install "$build_dir" --prefix "$work/prefix" >/dev/null
double="$(grep -E '^CONFORM_DOUBLE:BOOL=' "$build_dir/CMakeCache.txt" | cut -d= -f2)"

# The install holds exactly the API's headers (tests/installed_headers.txt): an internal header
# that leaks, or a public one that goes missing, fails here.
include="$work/prefix/include/conform"
installed="$(cd "$include" && find . -type f | sed 's|^\./||' | sort)"
expected="$(grep -v '^#' "$source_dir/tests/installed_headers.txt" | sort)"
if [[ "$installed" != "$expected" ]]; then
  diff <(echo "$expected") <(echo "$installed") >&2 || true
  fail "the installed headers differ from tests/installed_headers.txt (< expected, > installed)"
fi

# A project of the other Bullet precision is refused at configure time, with a message that
# says so; the same project with the package's precision configures.
precision_project() { # <dir> <line before find_package(Conform)>
  mkdir -p "$1"
  printf 'cmake_minimum_required(VERSION 3.25)\nproject(precision LANGUAGES CXX)\n%s\n%s\n' \
    "$2" 'find_package(Conform REQUIRED)' >"$1/CMakeLists.txt"
}
expect_precision_refused() { # <dir> <what the message must name> [cmake arguments]
  local dir="$1" source="$2"
  shift 2
  if cmake -S "$dir" -B "$dir/build" -DCMAKE_PREFIX_PATH="$work/prefix" "$@" >"$dir/log" 2>&1; then
    fail "a project using $wrong-precision Bullet ($source) configured against the $mine package"
  fi
  local said
  said="$(tr -s ' \n' '  ' <"$dir/log")"
  grep -qF "built against $mine-precision Bullet, but this project uses $wrong-precision Bullet ($source" \
    <<<"$said" || { cat "$dir/log"; fail "the precision mismatch was refused without its message"; }
}
if [[ "$double" == ON ]]; then
  mine=double wrong=float
  precision_project "$work/wrong-find" 'find_package(Bullet REQUIRED CONFIG CONFIGS BulletConfig.cmake)'
  expect_precision_refused "$work/wrong-find" "its find_package(Bullet)"
  precision_project "$work/right" 'find_package(Bullet REQUIRED CONFIG CONFIGS BulletConfig-float64.cmake)'
else
  mine=float wrong=double
  precision_project "$work/wrong-flags" ''
  expect_precision_refused "$work/wrong-flags" "BT_USE_DOUBLE_PRECISION in CMAKE_CXX_FLAGS" \
    -DCMAKE_CXX_FLAGS=-DBT_USE_DOUBLE_PRECISION
  precision_project "$work/wrong-definition" 'add_compile_definitions(BT_USE_DOUBLE_PRECISION)'
  expect_precision_refused "$work/wrong-definition" "BT_USE_DOUBLE_PRECISION in the directory"
  precision_project "$work/wrong-find" 'find_package(Bullet REQUIRED CONFIG CONFIGS BulletConfig-float64.cmake)'
  expect_precision_refused "$work/wrong-find" "its find_package(Bullet)"
  precision_project "$work/right" 'find_package(Bullet REQUIRED CONFIG CONFIGS BulletConfig.cmake)'
fi
cmake -S "$work/right" -B "$work/right/build" -DCMAKE_PREFIX_PATH="$work/prefix" >"$work/right.log" 2>&1 ||
  { cat "$work/right.log"; fail "a project of the package's Bullet precision was refused"; }
echo "install_test: a project of $wrong-precision Bullet is refused at configure time, one of $mine configures"

# What configure time cannot see, a single target of the other precision, the package's headers
# refuse at compile time (precision.hpp), naming both precisions.
mkdir -p "$work/wrong-target"
cp "$work/right/CMakeLists.txt" "$work/wrong-target/CMakeLists.txt"
printf '#include "conform/bullet/plugin.hpp"\nint main() { return 0; }\n' >"$work/wrong-target/main.cpp"
if [[ "$mine" == float ]]; then
  target_line='target_compile_definitions(app PRIVATE BT_USE_DOUBLE_PRECISION)'
  expected="built against float-precision Bullet, but this translation unit defines BT_USE_DOUBLE_PRECISION"
else
  target_line='target_compile_options(app PRIVATE -UBT_USE_DOUBLE_PRECISION)'
  expected="built against double-precision Bullet, but this translation unit does not define"
fi
printf 'add_executable(app main.cpp)\ntarget_link_libraries(app PRIVATE conform::bullet)\n%s\n' \
  "$target_line" >>"$work/wrong-target/CMakeLists.txt"
cmake -S "$work/wrong-target" -B "$work/wrong-target/build" -DCMAKE_PREFIX_PATH="$work/prefix" \
  >"$work/wrong-target.log" 2>&1 ||
  { cat "$work/wrong-target.log"; fail "the single-target project did not configure"; }
if cmake --build "$work/wrong-target/build" >>"$work/wrong-target.log" 2>&1; then
  fail "a target of $wrong-precision Bullet ($target_line) compiled against the $mine package"
fi
grep -qF "$expected" "$work/wrong-target.log" ||
  { cat "$work/wrong-target.log"; fail "the single target's precision was refused without its message"; }
echo "install_test: a single target of $wrong-precision Bullet is refused at compile time"

# A package built with CONFORM_SANITIZE holds instrumented code: its consumers must be built
# with the same sanitizers (their runtime), as the sanitized CI stage does.
sanitize_flags="-fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer"
consumer_flags=()
sanitized_package=0
if grep -qE '^CONFORM_SANITIZE:BOOL=ON' "$build_dir/CMakeCache.txt"; then
  consumer_flags=("-DCMAKE_CXX_FLAGS=$sanitize_flags")
  sanitized_package=1
fi
cmake -S "$source_dir/tests/consumer" -B "$work/build" -DCMAKE_PREFIX_PATH="$work/prefix" \
  -DCMAKE_BUILD_TYPE=Release -DCMAKE_EXPORT_COMPILE_COMMANDS=ON "${consumer_flags[@]}" >/dev/null
cmake --build "$work/build" >/dev/null

# What the consumer was compiled and linked with.
consumer_compile="$(grep -E '"command": .*main\.cpp' "$work/build/compile_commands.json" || true)"
[[ -n "$consumer_compile" ]] || fail "no compile command for the consumer"
if grep -qE -- '-fopenmp|CONFORM_VERSION' <<<"$consumer_compile"; then
  fail "the consumer is compiled with flags of Conform's build: $consumer_compile"
fi
grep -qE -- '-std=(c|gnu)\+\+20' <<<"$consumer_compile" ||
  fail "the consumer is not compiled as C++20 (cxx_std_20 not passed on)"
if readelf -d "$work/build/consumer" | grep -q 'assimp'; then
  fail "the Bullet consumer links assimp: $(readelf -d "$work/build/consumer" | grep assimp)"
fi
readelf -d "$work/build/importer" | grep -q 'assimp' || fail "the importer does not link assimp"

"$work/build/consumer"
"$work/build/importer" arm
model=/usr/share/assimp/models/OBJ/box.obj
if [[ -r "$model" ]]; then "$work/build/importer" "$model"; fi
# The whole application: a rigged model playing (a real one when assimp-testmodels is there).
character=/usr/share/assimp/models/X/anim_test.x
[[ -r "$character" ]] || character=arm
"$work/build/application" "$character"

# The same application built with ASan and UBSan against the (unsanitized) package: no report.
# Skipped, with a warning, where a sanitized program cannot start (address-space limits).
# (A sanitized package's consumers above already were.)
echo 'int main() { return 0; }' >"$work/probe.cpp"
if [[ $sanitized_package == 1 ]]; then
  echo "install_test: the package is sanitized, so the consumers above ran under ASan+UBSan"
elif c++ -fsanitize=address,undefined "$work/probe.cpp" -o "$work/probe" >/dev/null 2>&1 &&
  "$work/probe" >/dev/null 2>&1; then
  cmake -S "$source_dir/tests/consumer" -B "$work/build-sanitize" -DCMAKE_PREFIX_PATH="$work/prefix" \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    "-DCMAKE_CXX_FLAGS=$sanitize_flags" \
    >/dev/null
  cmake --build "$work/build-sanitize" --target application >/dev/null
  ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    "$work/build-sanitize/application" "$character" >"$work/sanitized.log" 2>&1 ||
    { cat "$work/sanitized.log"; fail "the sanitized application failed or reported"; }
  echo "install_test: the application under ASan+UBSan: $(tail -1 "$work/sanitized.log")"
else
  echo "install_test: WARNING: an ASan+UBSan program cannot start here; the sanitized run is skipped" >&2
fi
echo "install_test: find_package(Conform) from $work/prefix works (CONFORM_DOUBLE=$double);" \
  "the Bullet consumer links no assimp and compiles with no Conform flags"
