#!/usr/bin/env bash
# The layer order of core (ARCHITECTURE.md): cga -> mesh -> {skin, membrane} -> {ik, io}. A file of one
# layer (its public header, private header or source) may include only its own layer and the
# layers it is allowed to see below it; core never includes Bullet or the plugin.
# The command's libraries in scenes/ keep their own order, cli -> sweep -> kinds -> render -> base:
# a file of one (a folder under scenes/) includes only its own and the ones after it, each header
# by its path under scenes/ ("base/progress.hpp").
# Arguments: <conform binary (unused)> <source dir> [<build dir> (unused)].
set -euo pipefail
source_dir="$2"
core="$source_dir/core"

# What each layer may include, itself included. ik needs only the algebra; io reads and writes
# skinned meshes and rigs, so it sees everything below it but not ik.
declare -A allowed=(
  [cga]="cga"
  [mesh]="cga mesh"
  [skin]="cga mesh skin"
  [membrane]="cga mesh membrane"
  [ik]="cga ik"
  [io]="cga mesh skin io"
)

# The layer of a core file: its folder under include/conform, internal/conform or src
# (the umbrella cga.hpp belongs to cga; version.* to no layer, and anyone may include it).
layer_of() {
  local rel="${1#"$core"/}"
  rel="${rel#include/conform/}"
  rel="${rel#internal/conform/}"
  rel="${rel#src/}"
  case "$rel" in
    cga.hpp) echo cga ;;
    */*) echo "${rel%%/*}" ;;
    *) echo "" ;;
  esac
}

failures=0
checked=0
fail() {
  echo "layering_test: $*" >&2
  failures=$((failures + 1))
}

while IFS= read -r file; do
  checked=$((checked + 1))
  layer="$(layer_of "$file")"
  [[ -z "$layer" ]] && continue
  if [[ -z "${allowed[$layer]+set}" ]]; then
    fail "$file: folder '$layer' is not a known layer (add it to tests/layering_test.sh)"
    continue
  fi
  while IFS= read -r line; do
    number="${line%%:*}"
    target="$(sed -E 's/^[^:]*:[[:space:]]*#[[:space:]]*include[[:space:]]*[<"]([^">]+)[">].*/\1/' <<<"$line")"
    case "$target" in
      conform/bullet/* | bt*.h | BulletSoftBody/* | BulletDynamics/* | BulletCollision/* | \
        LinearMath/* | BulletInverseDynamics/*)
        fail "$file:$number: core includes Bullet or the plugin ($target)"
        continue
        ;;
      conform/version.hpp) continue ;;
      conform/cga.hpp) included=cga ;;
      conform/*/*) included="$(cut -d/ -f2 <<<"$target")" ;;
      *) continue ;;  # the standard library, Eigen, assimp, ...
    esac
    if [[ " ${allowed[$layer]} " != *" $included "* ]]; then
      fail "$file:$number: layer '$layer' includes '$target' of layer '$included'" \
        "(allowed: ${allowed[$layer]})"
    fi
  done < <(grep -nE '^[[:space:]]*#[[:space:]]*include' "$file" || true)
done < <(for dir in "$core/include" "$core/internal" "$core/src"; do
  [[ -d "$dir" ]] && find "$dir" -type f \( -name '*.hpp' -o -name '*.h' -o -name '*.cpp' -o -name '*.in' \)
done | sort)

((checked > 0)) || fail "no source files under $core"

# scenes/: what each library may include, itself included.
scenes="$source_dir/scenes"
declare -A scene_allowed=(
  [base]="base"
  [render]="render base"
  [kinds]="kinds render base"
  [sweep]="sweep kinds render base"
  [cli]="cli sweep kinds render base"
)
scene_checked=0
while IFS= read -r file; do
  scene_checked=$((scene_checked + 1))
  rel="${file#"$scenes"/}"
  if [[ "$rel" != */* ]]; then
    fail "$file: not in a library folder of scenes/ (cli, sweep, kinds, render, base)"
    continue
  fi
  lib="${rel%%/*}"
  if [[ -z "${scene_allowed[$lib]+set}" ]]; then
    fail "$file: folder '$lib' is not a known library of scenes/ (add it to tests/layering_test.sh)"
    continue
  fi
  while IFS= read -r line; do
    number="${line%%:*}"
    # Matched in bash, not by a sed per line: the scenes hold well over a thousand includes.
    [[ "$line" =~ ^[^:]*:[[:space:]]*#[[:space:]]*include[[:space:]]*([\<\"])([^\">]+) ]] || continue
    quote="${BASH_REMATCH[1]}"
    path="${BASH_REMATCH[2]}"
    included="${path%%/*}"
    if [[ "$path" == */* && -n "${scene_allowed[$included]+set}" ]]; then
      if [[ " ${scene_allowed[$lib]} " != *" $included "* ]]; then
        fail "$file:$number: library '$lib' includes '$path' of library '$included'" \
          "(allowed: ${scene_allowed[$lib]})"
      fi
    elif [[ "$quote" == '"' && "$path" != conform/* ]]; then
      # A directory-local or relative include would hide which library the header is in.
      fail "$file:$number: '$path' is not included by its path under scenes/ (LIBRARY/NAME.hpp)"
    fi
  done < <(grep -nE '^[[:space:]]*#[[:space:]]*include' "$file" || true)
done < <(find "$scenes" -type f \( -name '*.hpp' -o -name '*.h' -o -name '*.cpp' -o -name '*.in' \) | sort)

((scene_checked > 0)) || fail "no source files under $scenes"
if ((failures > 0)); then
  echo "layering_test: $failures include(s) break the layer order" >&2
  exit 1
fi
echo "layering_test: $checked files of core include only downwards" \
  "(cga -> mesh -> skin -> ik, io), and never Bullet;" \
  "$scene_checked files of scenes only downwards (cli -> sweep -> kinds -> render -> base)"
