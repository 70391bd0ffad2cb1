#!/usr/bin/env bash
# Issue 17's table: every layout, compact and not, on the room at 1M and 8M triangles and on
# three scanned meshes subdivided twice, primary (single and in packets) and diffuse rays, agreement against robust
# Embree; and the leak test of the wide layouts on a closed sphere and room.
# Usage: bench/wide_suite.sh [OUT_DIR] [WAVETRACE]   (JSON per run in OUT_DIR, default out/wide)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
out=${1:-$root/out/wide}
wavetrace=${2:-$root/build/wavetrace}
mkdir -p "$out"

accels=embree,embree:mode=compact,bvh,bvh:width=8,raystrips,raystrips:width=8,hmq,hmq:width=8
run() {  # NAME SCENE [--set ...]
  local name=$1 scene=$2
  shift 2
  for rays in primary diffuse; do
    "$wavetrace" bench accel --scene "$scene" "$@" --accel "$accels" --rays "$rays" --count 500000 --threads 2 \
      --repeat 5 --reference embree:mode=robust --json "$out/${name}_${rays}.json"
  done
  # Camera rays through intersect_coherent, where a layout has packets (raystrips, hmq:width=8).
  "$wavetrace" bench accel --scene "$scene" "$@" --accel "$accels" --rays primary --packets --count 500000 \
    --threads 2 --repeat 5 --reference embree:mode=robust --json "$out/${name}_packets.json"
}
run room_1M builtin:room:1M
run room_8M builtin:room:8M
for mesh in bunny00 diplodocus bear; do
  run "${mesh}_sub2" "$root/data/$mesh.off" --set scene.subdivide=2
done
for scene in sphere:1M room:1M; do
  "$wavetrace" bench leak --scene "builtin:$scene" --accel embree:mode=robust,hmq,hmq:width=8,raystrips,raystrips:width=8 \
    --count 10000000 --json "$out/leak_${scene/:/_}.json"
done
