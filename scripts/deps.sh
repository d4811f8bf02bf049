#!/usr/bin/env bash
# Installs the Debian packages Conform needs, only those that are missing.
# Usage: scripts/deps.sh [run|all]   (default: all; runs apt-get through sudo when not root)
#   run  what `conform` and its default scene need: the build tools, the libraries the command
#        links, and the programs that draw its plots, pictures and video (scripts/run.sh)
#   all  run, plus what the tests, benchmarks, Python module, fuzzing and the character
#        scene's default model need (scripts/build.sh, scripts/test.sh and so CI)
set -euo pipefail

profile="${1:-all}"

run_packages=(
  build-essential cmake ninja-build pkg-config  # the compiler and the build
  libeigen3-dev    # linear algebra (core)
  libbullet-dev    # the physics engine (plugin)
  libassimp-dev    # model import (conform::io)
  libcli11-dev     # the command line of conform
  nlohmann-json3-dev  # scene files and summary.json
  libtinygltf-dev  # run.glb (glTF 2.0 binary)
  libcairo2-dev libpng-dev  # the pictures: panels side by side, captions, a colour bar
  gnuplot-nox      # the PNG plots
  f3d xvfb         # the pictures: f3d renders them on a virtual X display (Xvfb)
  ffmpeg           # the video of the pictures (run.gif / run.mp4)
)

all_packages=(
  "${run_packages[@]}"
  libgtest-dev libgmock-dev  # the GoogleTest suite (tests/)
  libbenchmark-dev           # the Google Benchmark programs (benchmarks/)
  libcgal-dev      # optional: the cut's caps (constrained Delaunay) and the cut benchmark's CGAL clip
  assimp-testmodels  # the models of the tests and the character scene's default huesitos.fbx
  xauth            # xvfb-run, which the render tests call
  slurmctld slurmd slurm-client munge  # sweep_slurm_test: a one-node Slurm cluster
  clang-14 libclang-rt-14-dev libomp-dev  # scripts/fuzz.sh: libFuzzer targets, clang's OpenMP
  pybind11-dev python3-dev  # the Python module conform (python/), for Debian's /usr/bin/python3
  python3-numpy python3-pytest  # its arrays and its test suite (ctest python_test)
  python3-matplotlib  # examples/python: the plots
  python3-meshio  # conform run's ParaView series (outputs.vtk, --vtk): it writes the .vtu files
)

case "$profile" in
  run) packages=("${run_packages[@]}") ;;
  all) packages=("${all_packages[@]}") ;;
  *)
    echo "usage: scripts/deps.sh [run|all]" >&2
    exit 2
    ;;
esac

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if ((${#missing[@]} == 0)); then
  exit 0
fi

echo "conform: installing missing Debian packages: ${missing[*]}"
if [[ $(id -u) -eq 0 ]]; then
  SUDO=()
else
  SUDO=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${SUDO[@]}" apt-get update -qq
"${SUDO[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
