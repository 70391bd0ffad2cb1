#!/usr/bin/env bash
# Issue 33's table: Embree (native and AVX2 kernels), bvh:width=8, raystrips:width=8 and
# hmq:width=8 on the rooms at 1M and 8M triangles and three scans subdivided twice, camera and
# diffuse rays, one thread on one core, each accelerator timed in turn in ROUNDS rounds of one
# process a row (bench accel's rounds), then the table with its goals checked.
# Usage: bench/per_ray_suite.sh [OUT_DIR] [WAVETRACE]   (ROUNDS=9 COUNT=500000 CORE=0 by default)
# Nothing else may run meanwhile: this machine has two cores.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
out=${1:-$root/out/per_ray}
wavetrace=${2:-$root/build/wavetrace}
rounds=${ROUNDS:-9}
count=${COUNT:-500000}
core=${CORE:-0}
mkdir -p "$out"
accels=embree,embree:isa=avx2,bvh:width=8,raystrips:width=8,hmq:width=8
run() {  # NAME SCENE [--set ...]
  local name=$1 scene=$2
  shift 2
  for rays in primary diffuse; do
    taskset -c "$core" "$wavetrace" bench accel --scene "$scene" "$@" --accel "$accels" --rays "$rays" --count "$count" \
      --threads 1 --repeat "$rounds" --json "$out/${name}_${rays}.json" > "$out/${name}_${rays}.txt"
  done
}
run room_1M builtin:room:1M
run room_8M builtin:room:8M
for mesh in bunny00 diplodocus bear; do
  run "${mesh}_sub2" "$root/data/$mesh.off" --set scene.subdivide=2
done
# The machine's CPU as /proc/cpuinfo names it (a VM may give only the maker), with its family
# and model, and the AVX-512 flags Embree picks its kernels by.
field() { grep -m1 "^$1" /proc/cpuinfo | sed 's/.*: //'; }
echo "CPU: $(field "model name"), family $(field "cpu family") model $(field "model")" > "$out/cpu.txt"
grep -m1 "^flags" /proc/cpuinfo | tr ' ' '\n' | grep '^avx512' | tr '\n' ' ' | sed 's/^/AVX-512: /' >> "$out/cpu.txt"
python3 "$root/bench/per_ray_table.py" "$out"
