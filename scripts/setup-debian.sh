#!/usr/bin/env bash
# Installs, with apt-get, the Debian 12 packages evcorner needs to build and test,
# skipping those already present. Run as root, or with sudo available.
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  libfmt-dev libcli11-dev nlohmann-json3-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  zlib1g-dev libpng-dev libcairo2-dev fonts-dejavu-core
  liblz4-dev libzstd-dev libhdf5-dev hdf5-filter-plugin hdf5-filter-plugin-blosc-serial
  clang libclang-rt-14-dev
  libsqlite3-dev libbz2-dev liblzma-dev libmatio-dev
  python3-dev pybind11-dev python3-numpy python3-pytest python3-dask python3-distributed
  python3-venv python3-pip python3-setuptools python3-wheel
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

echo "setup: installing ${missing[*]}" >&2
sudo=()
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "setup: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
  sudo=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo[@]}" apt-get update -qq
"${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
