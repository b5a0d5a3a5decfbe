#!/usr/bin/env bash
# Set up chansph on Debian 12: install the missing Debian packages, configure and build into
# build/. Idempotent: a second run installs nothing and rebuilds only what changed.
# usage: jobs/setup.sh            (as root, or with sudo available)
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
cd "$here"

packages=(build-essential cmake pkg-config openmpi-bin libopenmpi-dev libhdf5-openmpi-dev
          hdf5-tools libnetcdf-mpi-dev netcdf-bin nco libfftw3-dev libinih-dev librandom123-dev
          python3 python3-numpy python3-netcdf4 python3-h5py python3-matplotlib python3-xarray
          clang-format)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing Debian packages: ${missing[*]}"
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq
  $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
else
  echo "setup: all Debian packages present"
fi

echo "setup: configuring build/ (Release, -O3)"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release > build.log 2>&1 || { cat build.log; exit 1; }
echo "setup: building"
cmake --build build -j"$(nproc)" >> build.log 2>&1 || { tail -50 build.log; exit 1; }
rm -f build.log
echo "setup: done, the program is build/chansph"
