#!/usr/bin/env bash
# Installs the Debian packages silentmpm needs. Idempotent: when everything is present it only
# checks (about a second) and exits. Needs root (or sudo) the first time.
set -euo pipefail
PKGS=(
  cmake g++ make pkg-config
  libgtest-dev                    # tests
  nlohmann-json3-dev libcli11-dev # case files, CLI
  libeigen3-dev                   # small fixed-size tensors
  libhdf5-openmpi-dev             # HDF5 snapshots (the flavour deal.II links)
  libdeal.ii-dev gmsh libgmsh-dev # FEM far-field and geometry
  python3-matplotlib python3-numpy python3-h5py   # study figures
  python3-meshio                  # tests: every XDMF output read back by a second reader
  clang libclang-rt-14-dev libomp-dev  # the fuzzed case loader (scripts/fuzz.sh)
)
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#PKGS[@]} packages present"
  exit 0
fi
echo "setup: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "setup: done"
