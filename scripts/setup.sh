#!/usr/bin/env bash
# One-step set-up on Debian 12 (as root): installs the missing Debian packages,
# extracts the CGAL demo meshes into data/, and configures and builds build/.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"

packages=(build-essential cmake pkg-config libembree-dev libtbb-dev libopenmesh-dev libglm-dev
  libopenexr-dev libimath-dev libtomlplusplus-dev libcli11-dev nlohmann-json3-dev libgtest-dev
  libbenchmark-dev libpng-dev libfmt-dev libxxhash-dev libnanoflann-dev python3-matplotlib libcgal-demo openmpi-bin libopenmpi-dev)
bash scripts/install_missing.sh "${packages[@]}"

# Real scanned and CAD meshes (OFF/PLY) from CGAL's demo data, e.g. data/bunny00.off.
if [[ ! -f data/bunny00.off ]]; then
  mkdir -p data
  tar -xzf /usr/share/doc/libcgal-dev/data.tar.gz -C data --strip-components=2 data/meshes
fi

cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)"
