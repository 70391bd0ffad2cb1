#!/usr/bin/env bash
# The BVH baseline's measurement matrix: bench accel on the 1M and 8M spheres, primary
# and diffuse rays, 1 and 2 threads; the leak test; the node-layout comparison.
# Usage: bench/accel_suite.sh [OUT_DIR]   (JSON and CSV per run land in OUT_DIR, default out/bench)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
out=${1:-$root/out/bench}
wavetrace=$root/build/wavetrace
mkdir -p "$out"

accels=embree,embree:mode=compact,bvh,bvh:width=8
for scene in builtin:sphere:1M builtin:sphere:8M; do
  for rays in primary diffuse; do
    for threads in 1 2; do
      name=$(echo "$scene" | tr ':' '_')_${rays}_t${threads}
      "$wavetrace" bench accel --scene "$scene" --accel "$accels" --rays "$rays" --count 1000000 \
        --threads "$threads" --repeat 5 --json "$out/$name.json"
    done
  done
done

"$wavetrace" bench leak --scene builtin:sphere:1M --accel embree,embree:mode=robust,bvh,bvh:width=8 \
  --count 10000000 --json "$out/leak_sphere_1M.json"

"$wavetrace" bench accel --scene builtin:sphere:8M \
  --accel bvh:layout=depth_first,bvh:layout=breadth_first,bvh:layout=veb,bvh:triangle_order=morton,bvh:layout=veb:triangle_order=morton \
  --rays diffuse --count 1000000 --threads 1 --repeat 5 --json "$out/layouts_sphere_8M.json"
