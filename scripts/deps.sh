#!/usr/bin/env bash
# Installs the Debian packages Conform needs, only those that are missing.
# Usage: scripts/deps.sh   (runs apt-get through sudo when not root)
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev libbullet-dev libassimp-dev assimp-testmodels
  libgtest-dev libgmock-dev libbenchmark-dev libomp-dev
  libcli11-dev nlohmann-json3-dev
  gnuplot-nox  # conform run draws its PNG plots with it
  libcgal-dev  # optional: the cut's caps (constrained Delaunay) and the cut benchmark's CGAL clip
  slurmctld slurmd slurm-client munge  # sweep_slurm_test: a one-node Slurm cluster
  f3d xvfb xauth  # conform run's pictures: f3d renders them under a virtual X display (xvfb-run)
  libcairo2-dev libpng-dev  # conform run's pictures: the panels side by side, a colour bar
  ffmpeg          # conform run's video of the pictures (run.gif / run.mp4)
  libtinygltf-dev # conform run's run.glb (glTF 2.0 binary)
  clang-14 libclang-rt-14-dev  # scripts/fuzz.sh: libFuzzer targets (CI's bounded fuzz run)
  pybind11-dev python3-dev  # the Python module conform (python/), for Debian's /usr/bin/python3
  python3-numpy python3-pytest  # its arrays and its test suite (ctest python_test)
  python3-matplotlib  # examples/python: the plots
  python3-meshio  # conform run's ParaView series (outputs.vtk, --vtk): it writes the .vtu files
)

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
