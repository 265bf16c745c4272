#!/usr/bin/env bash
# morphfem set-up on Debian 12: installs the missing Debian packages, configures
# and builds (build/), then optionally runs the demo scene or the test suite.
#
#   bash scripts/setup.sh --demo    install + build + run examples/inflate_tube.yaml
#   bash scripts/setup.sh --test    install + build + run every test (ctest)
#   bash scripts/setup.sh           install + build only
#
# Environment: BUILD_DIR (default build), JOBS (default: number of cores),
# MORPHFEM_WERROR=ON to treat warnings as errors (CI).
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(build-essential cmake pkg-config git
          petsc-dev libmumps-dev libmetis-dev libgmsh-dev libeigen3-dev
          libhdf5-openmpi-dev libyaml-cpp-dev libgtest-dev openmpi-bin
          libopenblas0-pthread python3 python3-matplotlib python3-numpy python3-h5py)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}"
  sudo_cmd=""
  [ "$(id -u)" -eq 0 ] || sudo_cmd="sudo"
  $sudo_cmd apt-get update -q
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

build_dir=${BUILD_DIR:-build}
jobs=${JOBS:-$(nproc)}
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release -DMORPHFEM_WERROR="${MORPHFEM_WERROR:-OFF}" >/dev/null
cmake --build "$build_dir" -j "$jobs"

# OpenMPI refuses to run as root unless told; these make mpirun work in containers.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1

case "${1:-}" in
  --demo)
    "$build_dir/app/morphfem" run examples/inflate_tube.yaml
    ;;
  --test)
    ctest --test-dir "$build_dir" --output-on-failure -j "$jobs" --timeout 900
    ;;
  "") ;;
  *) echo "setup: unknown option $1 (use --demo or --test)" >&2; exit 2 ;;
esac
