#!/usr/bin/env bash
# The library as another project uses it: installs BUILD (default build/) into a temporary
# prefix, configures examples/ against it with find_package(wavetrace), builds the examples
# and runs each on a small scene. Usage: scripts/check_examples.sh [BUILD]
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

cmake --install "$build" --prefix "$work/prefix" >/dev/null
echo "installed: $(find "$work/prefix/include/wavetrace" -name '*.hpp' | wc -l) headers, $(ls "$work/prefix/lib"/*.a | wc -l) libraries, $(ls "$work/prefix/lib/cmake/wavetrace" | tr "\n" " ")"
# The compiler the library was built with (a package's C++ ABI is its compiler's).
compiler=$(sed -n 's/^CMAKE_CXX_COMPILER:[A-Z]*=//p' "$build/CMakeCache.txt")
cmake -S "$root/examples" -B "$work/build" -DCMAKE_PREFIX_PATH="$work/prefix" -DCMAKE_BUILD_TYPE=Release \
  ${compiler:+-DCMAKE_CXX_COMPILER="$compiler"} >/dev/null
cmake --build "$work/build" -j"$(nproc)" >/dev/null
cd "$work"
"$work/build/ambient_occlusion/ambient_occlusion" builtin:room:20k --set render.threads=2
"$work/build/compare_heuristics/compare_heuristics" builtin:room:20k --set render.threads=2
"$work/build/hand_wired_pipeline/hand_wired_pipeline" builtin:sphere:2000
